//! The builtin functions of mrsl, one [`Builtin`] each, with what every stage
//! needs to know about them: the name a program calls them by, how a call is
//! typed ([`Builtin::signature`], which `check` applies), whether they are
//! derivatives (which `deriv` and codegen evaluate at a neighbouring sample),
//! and the WGSL function they become.
//!
//! The signatures are data rather than code so that the table reads like the
//! one in docs/language.md, section 7, and stays in step with it.

use crate::types::{self, Scalar, Type};

/// Declares [`Builtin`] with its mrsl names and one-line docs, so that they
/// cannot disagree.
macro_rules! builtins {
    ($($variant:ident = $name:literal: $doc:literal,)*) => {
        /// A builtin function.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum Builtin {
            $($variant,)*
        }

        /// Whether constant components `x` (and `y`, for two-argument builtins) lie
/// inside a builtin's domain.
pub type Domain = fn(f64, f64) -> bool;

impl Builtin {
            /// Every builtin.
            pub const ALL: &[Builtin] = &[$(Builtin::$variant,)*];

            /// The name a program calls it by.
            pub fn name(self) -> &'static str {
                match self {
                    $(Builtin::$variant => $name,)*
                }
            }

            /// What it computes, in a line (for an editor's hover and completion).
            pub fn doc(self) -> &'static str {
                match self {
                    $(Builtin::$variant => $doc,)*
                }
            }
        }
    };
}

builtins! {
    Sin = "sin": "The sine of an angle in radians.",
    Cos = "cos": "The cosine of an angle in radians.",
    Tan = "tan": "The tangent of an angle in radians.",
    Asin = "asin": "The arc sine, in radians; x from -1 to 1.",
    Acos = "acos": "The arc cosine, in radians; x from -1 to 1.",
    Atan = "atan": "The arc tangent, in radians.",
    Sinh = "sinh": "The hyperbolic sine.",
    Cosh = "cosh": "The hyperbolic cosine.",
    Tanh = "tanh": "The hyperbolic tangent.",
    Exp = "exp": "e raised to the power x.",
    Exp2 = "exp2": "2 raised to the power x.",
    Log = "log": "The natural logarithm; x > 0.",
    Log2 = "log2": "The base-2 logarithm; x > 0.",
    Sqrt = "sqrt": "The square root; x >= 0.",
    InverseSqrt = "inversesqrt": "1 / sqrt(x); x > 0.",
    Floor = "floor": "The largest integer not above x.",
    Ceil = "ceil": "The smallest integer not below x.",
    Fract = "fract": "x - floor(x).",
    Round = "round": "x rounded to the nearest integer, halves to even.",
    Trunc = "trunc": "x rounded towards zero.",
    Saturate = "saturate": "x clamped to 0 to 1.",
    Radians = "radians": "Degrees converted to radians.",
    Degrees = "degrees": "Radians converted to degrees.",
    Abs = "abs": "The absolute value (int, uint, float or a vector of one).",
    Sign = "sign": "-1, 0 or 1 by the sign of x (not uint).",
    Pow = "pow": "x raised to the power y; x >= 0.",
    Atan2 = "atan2": "The angle of the point (x, y) from the x axis, atan2(y, x), in radians.",
    Step = "step": "0 where x < edge, else 1: step(edge, x); edge may be a scalar.",
    Min = "min": "The smaller of two values; either may be a scalar.",
    Max = "max": "The larger of two values; either may be a scalar.",
    Clamp = "clamp": "x clamped to lo to hi: clamp(x, lo, hi); lo and hi may be scalars.",
    Mix = "mix": "The linear blend a + (b - a) t: mix(a, b, t); t may be a scalar.",
    Lerp = "lerp": "The same as mix: lerp(a, b, t).",
    Smoothstep = "smoothstep": "The Hermite step from 0 at e0 to 1 at e1: smoothstep(e0, e1, x).",
    Dot = "dot": "The dot product of two vectors of one type.",
    Cross = "cross": "The cross product of two float3s.",
    Normalize = "normalize": "The vector scaled to length 1.",
    Length = "length": "The length of a vector (the absolute value of a scalar).",
    Distance = "distance": "The distance between two points.",
    Reflect = "reflect": "The incident direction i reflected about the normal n: reflect(i, n).",
    Refract = "refract": "The incident direction refracted through the normal with ratio eta: refract(i, n, eta).",
    FaceForward = "faceforward": "n, or -n where dot(nref, i) >= 0: faceforward(n, i, nref).",
    Determinant = "determinant": "The determinant of a square matrix.",
    Transpose = "transpose": "The transpose of a square matrix.",
    Any = "any": "Whether any component is true.",
    All = "all": "Whether every component is true.",
    Ddx = "ddx": "The difference of x to the neighbouring sample in x (effect bodies only).",
    Ddy = "ddy": "The difference of x to the neighbouring sample in y (effect bodies only).",
    Fwidth = "fwidth": "abs(ddx(x)) + abs(ddy(x)) (effect bodies only).",
    DdxSurface = "ddx_surface": "ddx, taken on this side of the effect's keys at coarse rate (effect bodies only).",
    DdySurface = "ddy_surface": "ddy, taken on this side of the effect's keys at coarse rate (effect bodies only).",
    FwidthSurface = "fwidth_surface": "fwidth, taken on this side of the effect's keys at coarse rate (effect bodies only).",
    Sample = "sample": "Samples a texture at uv with the gradients of uv: sample(texture, sampler, uv) (effect bodies only).",
    SampleLevel = "sample_level": "Samples a texture at uv at mip level lod: sample_level(texture, sampler, uv, lod).",
    SampleGrad = "sample_grad": "Samples a texture at uv with explicit gradients: sample_grad(texture, sampler, uv, ddx, ddy).",
    Load = "load": "Reads one texel without filtering: load(texture, int2 texel [, int level]).",
    TextureSize = "texture_size": "The size of a texture's level 0 in texels, as an int2.",
}

/// How a call to a builtin is typed: how many arguments it takes, what their
/// types must be, and the type of the result.
#[derive(Debug, Clone)]
pub struct Signature {
    pub arity: Arity,
    pub rule: Rule,
    pub returns: Returns,
}

/// How many arguments a builtin takes.
#[derive(Debug, Clone, Copy)]
pub struct Arity {
    pub min: usize,
    pub max: usize,
    /// The parameters by name, where the count alone would not say what goes
    /// where (the texture builtins); empty otherwise.
    pub params: &'static str,
}

/// What the argument types must be.
#[derive(Debug, Clone)]
pub enum Rule {
    /// One argument of class `accept`.
    Unary { accept: Accept },
    /// Every argument of one generic type `T` of class `accept`. A scalar in
    /// a `widen` position may stand for a vector `T`: it is splatted to it,
    /// as WGSL wants every generic argument of the same type.
    Generic { accept: Accept, widen: &'static [usize] },
    /// `same` arguments of one exact type of class `accept`, then, if `then`
    /// is given, one that converts to it. `what` says it all in the error.
    Vectors { accept: Accept, same: usize, then: Option<Type>, what: &'static str },
    /// A `texture2d`, a `sampler`, then coordinates that convert to `coords`.
    Sample { coords: &'static [Type] },
    /// A `texture2d`, `int2` texel coordinates and an optional `int` level.
    Load,
}

/// A class of argument types.
#[derive(Debug, Clone)]
pub enum Accept {
    /// `float`, `floatN`, or a literal.
    Float,
    /// `int`, `uint`, `float`, their vectors, or a literal.
    Number,
    /// Like [`Accept::Number`], but not `uint` (`sign`).
    Signed,
    /// `floatN`.
    FloatVector,
    /// `intN`, `uintN` or `floatN`.
    NumberVector,
    /// A matrix.
    Matrix,
    /// `bool` or `boolN`.
    Bool,
    /// This type and no other.
    Exactly(Type),
}

/// The type of the result.
#[derive(Debug, Clone)]
pub enum Returns {
    /// The argument type `T`. A literal `T` becomes `float` for the float
    /// classes, and `int` or `float` by its kind for the number classes.
    Arg,
    /// The element type of `T` (`dot`).
    Element,
    /// Always this type.
    Fixed(Type),
}

const FLOAT2: Type = Type::Vector(Scalar::Float, 2);
const FLOAT3: Type = Type::Vector(Scalar::Float, 3);
const FLOAT4: Type = Type::Vector(Scalar::Float, 4);

impl Builtin {
    /// The builtin a program calls `name`, if any. Builtin names are reserved:
    /// nothing else may be declared with one.
    pub fn from_name(name: &str) -> Option<Builtin> {
        Builtin::ALL.iter().copied().find(|b| b.name() == name)
    }

    /// How a call is typed; see docs/language.md, section 7, for the same
    /// table in prose.
    pub fn signature(self) -> Signature {
        use Builtin::*;
        let unary = |accept, returns| Signature { arity: Arity::exactly(1), rule: Rule::Unary { accept }, returns };
        let generic = |n, accept, widen, returns| Signature {
            arity: Arity::exactly(n),
            rule: Rule::Generic { accept, widen },
            returns,
        };
        let vectors = |accept, same, then: Option<Type>, what, returns| Signature {
            arity: Arity::exactly(same + usize::from(then.is_some())),
            rule: Rule::Vectors { accept, same, then, what },
            returns,
        };
        let sample = |params, coords: &'static [Type]| Signature {
            arity: Arity { min: 2 + coords.len(), max: 2 + coords.len(), params },
            rule: Rule::Sample { coords },
            returns: Returns::Fixed(FLOAT4),
        };
        match self {
            Sin | Cos | Tan | Asin | Acos | Atan | Sinh | Cosh | Tanh | Exp | Exp2 | Log | Log2 | Sqrt
            | InverseSqrt | Floor | Ceil | Fract | Round | Trunc | Saturate | Radians | Degrees | Ddx | Ddy
            | Fwidth | DdxSurface | DdySurface | FwidthSurface => unary(Accept::Float, Returns::Arg),
            Abs => unary(Accept::Number, Returns::Arg),
            Sign => unary(Accept::Signed, Returns::Arg),
            Pow | Atan2 => generic(2, Accept::Float, &[], Returns::Arg),
            Step => generic(2, Accept::Float, &[0], Returns::Arg),
            Min | Max => generic(2, Accept::Number, &[0, 1], Returns::Arg),
            Clamp => generic(3, Accept::Number, &[1, 2], Returns::Arg),
            Mix | Lerp => generic(3, Accept::Float, &[2], Returns::Arg),
            Smoothstep => generic(3, Accept::Float, &[0, 1], Returns::Arg),
            Dot => vectors(Accept::NumberVector, 2, None, "two vectors of the same type", Returns::Element),
            Cross => vectors(Accept::Exactly(FLOAT3), 2, None, "two `float3`s", Returns::Arg),
            Normalize => unary(Accept::FloatVector, Returns::Arg),
            Length => unary(Accept::Float, Returns::Fixed(types::FLOAT)),
            Distance => generic(2, Accept::Float, &[], Returns::Fixed(types::FLOAT)),
            Reflect => vectors(Accept::FloatVector, 2, None, "two float vectors of the same size", Returns::Arg),
            Refract => vectors(
                Accept::FloatVector,
                2,
                Some(types::FLOAT),
                "(floatN incident, floatN normal, float eta)",
                Returns::Arg,
            ),
            FaceForward => vectors(Accept::FloatVector, 3, None, "three float vectors of the same size", Returns::Arg),
            Determinant => unary(Accept::Matrix, Returns::Fixed(types::FLOAT)),
            Transpose => unary(Accept::Matrix, Returns::Arg),
            Any | All => unary(Accept::Bool, Returns::Fixed(types::BOOL)),
            Sample => sample("texture, sampler, float2 uv", &[FLOAT2]),
            SampleLevel => sample("texture, sampler, float2 uv, float lod", &[FLOAT2, types::FLOAT]),
            SampleGrad => sample("texture, sampler, float2 uv, float2 ddx, float2 ddy", &[FLOAT2, FLOAT2, FLOAT2]),
            Load => Signature {
                arity: Arity { min: 2, max: 3, params: "texture, int2 coord [, int level]" },
                rule: Rule::Load,
                returns: Returns::Fixed(FLOAT4),
            },
            TextureSize => unary(Accept::Exactly(Type::Texture2d), Returns::Fixed(Type::Vector(Scalar::Int, 2))),
        }
    }

    /// The argument a derivative differentiates (`sample`: its uv), or `None`
    /// for a builtin that is not a derivative. Compute shaders have no
    /// hardware derivatives, so `deriv` plans and codegen emits a second
    /// evaluation of this argument at the neighbouring sample.
    pub fn derivative_operand(self) -> Option<usize> {
        match self {
            Builtin::Ddx
            | Builtin::Ddy
            | Builtin::Fwidth
            | Builtin::DdxSurface
            | Builtin::DdySurface
            | Builtin::FwidthSurface => Some(0),
            Builtin::Sample => Some(2),
            _ => None,
        }
    }

    /// Whether the builtin is a derivative (see [`Builtin::derivative_operand`]).
    pub fn is_derivative(self) -> bool {
        self.derivative_operand().is_some()
    }

    /// Whether the derivative stays on the effect's surface: its difference
    /// never spans one of the effect's discontinuity keys at coarse rate
    /// where the sample on the other side does not (docs/language.md,
    /// section 9).
    pub fn on_surface(self) -> bool {
        matches!(self, Builtin::DdxSurface | Builtin::DdySurface | Builtin::FwidthSurface)
    }

    /// The derivative without [`Builtin::on_surface`]'s rule: `ddx` for
    /// `ddx_surface`; itself for the others.
    pub fn plain_derivative(self) -> Builtin {
        match self {
            Builtin::DdxSurface => Builtin::Ddx,
            Builtin::DdySurface => Builtin::Ddy,
            Builtin::FwidthSurface => Builtin::Fwidth,
            other => other,
        }
    }

    /// Where the builtin is defined on constant arguments, as WGSL's constant
    /// evaluation (naga's) checks it when the shader is created: `None` for
    /// builtins without such a check, else whether the components `x` (and
    /// `y`, the second argument's, for `pow`) are inside the domain, and the
    /// domain in words.
    pub fn constant_domain(self) -> Option<(Domain, &'static str)> {
        use Builtin::*;
        Some(match self {
            Asin | Acos => (|x, _| x.abs() <= 1.0, "-1 <= x <= 1"),
            Log | Log2 => (|x, _| x > 0.0, "x > 0"),
            Sqrt => (|x, _| x >= 0.0, "x >= 0"),
            InverseSqrt => (|x, _| x > 0.0, "x > 0"),
            Pow => (
                |x, y| {
                    !(x < 0.0
                        || (x == 1.0 && y.is_infinite())
                        || (x.is_infinite() && y == 0.0)
                        || (x == 0.0 && y <= 0.0))
                },
                "x >= 0, and y > 0 where x = 0",
            ),
            _ => return None,
        })
    }

    /// The WGSL function a call becomes. The derivatives name WGSL's own,
    /// which exist in fragment shaders only: in our compute kernels codegen
    /// takes differences instead, and writes `sample` as `textureSampleGrad`
    /// with those differences as the gradients.
    pub fn wgsl_name(self) -> &'static str {
        match self {
            Builtin::InverseSqrt => "inverseSqrt",
            Builtin::Lerp => "mix",
            Builtin::FaceForward => "faceForward",
            Builtin::Ddx => "dpdx",
            Builtin::Ddy => "dpdy",
            Builtin::Sample | Builtin::SampleGrad => "textureSampleGrad",
            Builtin::SampleLevel => "textureSampleLevel",
            Builtin::Load => "textureLoad",
            Builtin::TextureSize => "textureDimensions",
            other => other.name(),
        }
    }
}

impl Arity {
    fn exactly(n: usize) -> Arity {
        Arity { min: n, max: n, params: "" }
    }

    pub fn accepts(self, n: usize) -> bool {
        (self.min..=self.max).contains(&n)
    }
}

impl std::fmt::Display for Arity {
    /// As the arity error says it: `1 argument`, `2 or 3 arguments (texture, ...)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.min, self.max) {
            (1, 1) => write!(f, "1 argument")?,
            (n, m) if n == m => write!(f, "{n} arguments")?,
            (n, m) => write!(f, "{n} or {m} arguments")?,
        }
        if !self.params.is_empty() {
            write!(f, " ({})", self.params)?;
        }
        Ok(())
    }
}

impl Accept {
    pub fn accepts(&self, ty: &Type) -> bool {
        match self {
            Accept::Float => ty.is_float_like(),
            Accept::Number => matches!(
                ty,
                Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                    | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
                    | Type::AbstractFloat
                    | Type::AbstractInt
            ),
            Accept::Signed => Accept::Number.accepts(ty) && ty.scalar() != Some(Scalar::Uint),
            Accept::FloatVector => matches!(ty, Type::Vector(Scalar::Float, _)),
            Accept::NumberVector => matches!(ty, Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)),
            Accept::Matrix => matches!(ty, Type::Matrix(_)),
            Accept::Bool => matches!(ty, Type::Scalar(Scalar::Bool) | Type::Vector(Scalar::Bool, _)),
            Accept::Exactly(t) => ty == t,
        }
    }

    /// Whether a literal `T` keeps its kind (`min(1, 2)` is an `int`) rather
    /// than becoming a `float`.
    pub fn keeps_literal_kind(&self) -> bool {
        matches!(self, Accept::Number | Accept::Signed)
    }
}

impl std::fmt::Display for Accept {
    /// As "`f` needs ..." says it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Accept::Float => write!(f, "a float or float vector"),
            Accept::Number | Accept::Signed => write!(f, "a number or vector"),
            Accept::FloatVector => write!(f, "a float vector"),
            Accept::NumberVector => write!(f, "a number vector"),
            Accept::Matrix => write!(f, "a matrix"),
            Accept::Bool => write!(f, "a bool vector"),
            Accept::Exactly(t) => write!(f, "a `{t}`"),
        }
    }
}

//! The builtin functions of mrsl, one [`Builtin`] each, with what every stage
//! needs to know about them: the name a program calls them by, how a call is
//! typed ([`Builtin::signature`], which `check` applies), whether they are
//! derivatives (which `deriv` and codegen evaluate at a neighbouring sample),
//! and the WGSL function they become.
//!
//! The signatures are data rather than code so that the table reads like the
//! one in docs/language.md, section 7, and stays in step with it.

use crate::types::{self, Scalar, Type};

/// Declares [`Builtin`] with its mrsl names, so that the two cannot disagree.
macro_rules! builtins {
    ($($variant:ident = $name:literal,)*) => {
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
        }
    };
}

builtins! {
    Sin = "sin",
    Cos = "cos",
    Tan = "tan",
    Asin = "asin",
    Acos = "acos",
    Atan = "atan",
    Sinh = "sinh",
    Cosh = "cosh",
    Tanh = "tanh",
    Exp = "exp",
    Exp2 = "exp2",
    Log = "log",
    Log2 = "log2",
    Sqrt = "sqrt",
    InverseSqrt = "inversesqrt",
    Floor = "floor",
    Ceil = "ceil",
    Fract = "fract",
    Round = "round",
    Trunc = "trunc",
    Saturate = "saturate",
    Radians = "radians",
    Degrees = "degrees",
    Abs = "abs",
    Sign = "sign",
    Pow = "pow",
    Atan2 = "atan2",
    Step = "step",
    Min = "min",
    Max = "max",
    Clamp = "clamp",
    Mix = "mix",
    Lerp = "lerp",
    Smoothstep = "smoothstep",
    Dot = "dot",
    Cross = "cross",
    Normalize = "normalize",
    Length = "length",
    Distance = "distance",
    Reflect = "reflect",
    Refract = "refract",
    FaceForward = "faceforward",
    Determinant = "determinant",
    Transpose = "transpose",
    Any = "any",
    All = "all",
    Ddx = "ddx",
    Ddy = "ddy",
    Fwidth = "fwidth",
    DdxSurface = "ddx_surface",
    DdySurface = "ddy_surface",
    FwidthSurface = "fwidth_surface",
    Sample = "sample",
    SampleLevel = "sample_level",
    SampleGrad = "sample_grad",
    Load = "load",
    TextureSize = "texture_size",
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

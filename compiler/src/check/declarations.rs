//! Top-level declarations: registering every global name before any body is
//! checked (so that items may refer to each other in any order), then each
//! declaration's own details: channel types and `@key`, uniform arrays and
//! defaults, effect types, `@nearest` and `@format`.

use super::formats::{default_output_format, formats_for, output_format_fits};
use super::{
    Background, COARSE_BLOCKS, Checker, ConstId, ConstInfo, ConstValue, EffectId, EffectInfo, FunctionId, FunctionInfo,
    Global, InputId, InputInfo, KeyCompare, UniformId, UniformInfo, UniformKind, err,
};
use crate::attributes::{self, Target};
use crate::builtins::Builtin;
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};

impl Checker<'_> {
    pub(super) fn register_globals(&mut self) {
        let program = self.out.program;
        // Pass 1: names, so that items may refer to each other in any order.
        for (index, item) in program.items.iter().enumerate() {
            self.register_name(item);
            self.register_item(index, item);
        }
        // Pass 2: declarations' own details (types allowed, attributes, defaults).
        let (mut input_i, mut uniform_i, mut const_i, mut effect_i) = (0, 0, 0, 0);
        for item in &program.items {
            match item {
                Item::Input(d) => {
                    self.check_input(InputId(input_i), d);
                    input_i += 1;
                }
                Item::Uniform(d) => {
                    self.check_uniform(UniformId(uniform_i), d);
                    uniform_i += 1;
                }
                Item::Const(_) => {
                    self.const_value(ConstId(const_i));
                    const_i += 1;
                }
                Item::Effect(d) => {
                    self.check_effect_decl(EffectId(effect_i), d);
                    effect_i += 1;
                }
                Item::Function(_) => {}
            }
        }
    }

    /// Binds the item's name to the id it is about to get (reported if
    /// reserved or defined twice).
    fn register_name(&mut self, item: &Item) {
        let name = item.name();
        // A reserved name is reported but still registered (unbound), so
        // that ids stay aligned with the items they index.
        let reserved = Builtin::from_name(&name.name).is_some() || Type::from_name(&name.name).is_some();
        if reserved {
            self.error(err(
                "E0103",
                format!("`{}` is a reserved name", name.name),
                name.span,
                "reserved: a builtin function or type",
            ));
        }
        let global = match item {
            Item::Input(_) => Global::Input(InputId(self.out.inputs.len() as u32)),
            Item::Uniform(_) => Global::Uniform(UniformId(self.out.uniforms.len() as u32)),
            Item::Const(_) => Global::Const(ConstId(self.out.consts.len() as u32)),
            Item::Function(_) => Global::Function(FunctionId(self.out.functions.len() as u32)),
            Item::Effect(_) => Global::Effect(EffectId(self.out.effects.len() as u32)),
        };
        if reserved {
        } else if let Some((_, first)) = self.globals.get(&name.name) {
            self.error(
                Diagnostic::error("E0101", format!("`{}` is defined twice", name.name))
                    .with_label(Label::primary(name.span, "defined again here"))
                    .with_label(Label::secondary(*first, "first defined here")),
            );
        } else {
            self.globals.insert(name.name.clone(), (global, name.span));
        }
    }

    /// The item's entry in the checked program, with its declared type;
    /// pass 2 and the bodies fill in the rest.
    fn register_item(&mut self, index: usize, item: &Item) {
        match item {
            Item::Input(d) => {
                let ty = self.resolve_type(&d.ty);
                self.out.inputs.push(InputInfo {
                    name: d.name.name.clone(),
                    ty,
                    key: None,
                    background: None,
                    decode: None,
                });
            }
            Item::Uniform(d) => {
                let ty = self.resolve_type(&d.ty);
                let kind = match ty {
                    Type::Texture2d => UniformKind::Texture,
                    Type::Sampler => UniformKind::Sampler,
                    _ => UniformKind::Value { default: None },
                };
                self.out.uniforms.push(UniformInfo { name: d.name.name.clone(), ty, kind });
            }
            Item::Const(d) => {
                let ty = self.resolve_type(&d.ty);
                self.out.consts.push(ConstInfo { name: d.name.name.clone(), ty, value: None, item: index });
            }
            Item::Function(d) => {
                let ret = self.resolve_type(&d.ret);
                self.out.functions.push(FunctionInfo {
                    name: d.name.name.clone(),
                    ret,
                    params: vec![],
                    item: index,
                    calls: vec![],
                });
            }
            Item::Effect(d) => {
                let ty = self.resolve_type(&d.ty);
                self.out.effects.push(EffectInfo {
                    name: d.name.name.clone(),
                    rate: d.rate,
                    // Checked in `check_effect_decl`: only the block sizes the kernels have.
                    block: d
                        .coarse_block
                        .and_then(|(n, _)| u32::try_from(n).ok())
                        .filter(|n| COARSE_BLOCKS.contains(n)),
                    ty,
                    item: index,
                    name_span: d.name.span,
                    deps: vec![],
                    has_refine: false,
                    nearest: false,
                    result: None,
                    format: None,
                });
            }
        }
    }

    fn check_input(&mut self, id: InputId, d: &InputDecl) {
        let ty = self.out.inputs[id.index()].ty.clone();
        let allowed = matches!(
            ty,
            Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
        );
        if !allowed && !ty.is_error() {
            self.error(
                err("E0104", format!("a G-buffer channel cannot have type `{ty}`"), d.ty.span, "not a channel type")
                    .with_note("channels are scalars or vectors of float, int or uint"),
            );
        }
        for attr in &d.attrs {
            match attr.name.name.as_str() {
                "key" => {
                    let key = match attr.args.as_slice() {
                        [] => Some(KeyCompare::Exact),
                        [arg] => match self.const_eval(arg) {
                            Some(v) if v.values.len() == 1 && v.values[0] >= 0.0 => {
                                Some(KeyCompare::Threshold { threshold: v.values[0] })
                            }
                            _ => {
                                self.error(err(
                                    "E0111",
                                    "`@key` threshold must be a non-negative number",
                                    arg.span,
                                    "expected a number",
                                ));
                                None
                            }
                        },
                        _ => {
                            self.error(err(
                                "E0111",
                                "`@key` takes at most one argument",
                                attr.span,
                                "too many arguments",
                            ));
                            None
                        }
                    };
                    if matches!(key, Some(KeyCompare::Threshold { .. }))
                        && ty.scalar() != Some(Scalar::Float)
                        && !ty.is_error()
                    {
                        self.error(err(
                            "E0111",
                            "a threshold key must be a float channel",
                            attr.span,
                            "use `@key` for exact comparison",
                        ));
                    }
                    self.out.inputs[id.index()].key = key;
                }
                "surface_key" => {
                    if let Some(key) = self.surface_key(attr, &ty) {
                        self.out.inputs[id.index()].key = Some(key);
                    }
                }
                "background" | "foreground" => {
                    let rule = self.background_rule(attr, &ty);
                    self.out.inputs[id.index()].background = rule;
                }
                "depth" | "encoded" | "packed" => self.channel_decode(id, attr, &ty),
                other => self.unknown_attribute(attr, other, &attributes::names_on(Target::Input)),
            }
        }
    }

    /// `@surface_key(normal, t)` on a `float3` position channel: the offset
    /// between two samples leaving either one's tangent plane by more than
    /// `t` of its length is a discontinuity (`KeyCompare::Surface`).
    fn surface_key(&mut self, attr: &Attribute, ty: &Type) -> Option<KeyCompare> {
        let float3 = Type::Vector(Scalar::Float, 3);
        let [normal, threshold] = attr.args.as_slice() else {
            self.error(
                err(
                    "E0111",
                    "`@surface_key` takes the normal channel and a threshold",
                    attr.span,
                    "expected two arguments",
                )
                .with_note("e.g. `@surface_key(normal, 0.25) in float3 position;`"),
            );
            return None;
        };
        if *ty != float3 && !ty.is_error() {
            self.error(err("E0111", "a surface key must be a `float3` position channel", attr.span, "not a `float3`"));
            return None;
        }
        let normal_input = match &normal.kind {
            ExprKind::Name(name) => self.out.inputs.iter().find(|i| i.name == *name),
            _ => None,
        };
        let normal_name = match normal_input {
            Some(input) if input.ty == float3 => input.name.clone(),
            _ => {
                self.error(err(
                    "E0111",
                    "the first argument of `@surface_key` must name a `float3` normal channel",
                    normal.span,
                    "not a `float3` channel",
                ));
                return None;
            }
        };
        match self.const_eval(threshold) {
            Some(v) if v.values.len() == 1 && (0.0..=1.0).contains(&v.values[0]) => {
                Some(KeyCompare::Surface { normal: normal_name, threshold: v.values[0] })
            }
            _ => {
                self.error(
                    err(
                        "E0111",
                        "a surface key's threshold must be a number from 0 to 1",
                        threshold.span,
                        "expected a number",
                    )
                    .with_note(
                        "it is the sine of the angle at which the offset between two samples leaves the surface",
                    ),
                );
                None
            }
        }
    }

    /// `@background(v)` (pixels where the channel is `v`) or `@foreground(v)`
    /// (where it is not) on a scalar channel.
    fn background_rule(&mut self, attr: &Attribute, ty: &Type) -> Option<Background> {
        let which = attr.name.name.as_str();
        let [value] = attr.args.as_slice() else {
            self.error(err("E0111", format!("`@{which}` takes one value"), attr.span, "expected one argument"));
            return None;
        };
        if ty.components() != 1 && !ty.is_error() {
            self.error(err("E0111", format!("`@{which}` must be on a scalar channel"), attr.span, "not a scalar"));
            return None;
        }
        let Some(v) = self.const_eval(value).filter(|v| v.values.len() == 1) else {
            self.error(err("E0111", format!("`@{which}` takes a constant"), value.span, "not a constant"));
            return None;
        };
        let v = v.values[0];
        let fits = match ty.scalar() {
            Some(Scalar::Uint) => v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0,
            Some(Scalar::Int) => v >= f64::from(i32::MIN) && v <= f64::from(i32::MAX) && v.fract() == 0.0,
            _ => v.is_finite(),
        };
        if !fits && !ty.is_error() {
            self.error(err(
                "E0111",
                format!("`@{which}` value does not fit the channel's type `{ty}`"),
                value.span,
                "out of range",
            ));
            return None;
        }
        Some(if which == "background" { Background::Equal { value: v } } else { Background::NotEqual { value: v } })
    }

    fn unknown_attribute(&mut self, attr: &Attribute, name: &str, known: &[&str]) {
        let list = known.iter().map(|k| format!("`@{k}`")).collect::<Vec<_>>().join(", ");
        self.error(
            err("E0110", format!("unknown attribute `@{name}` here"), attr.span, "not allowed on this declaration")
                .with_note(if known.is_empty() {
                    "this declaration takes no attributes".to_string()
                } else {
                    format!("allowed here: {list}")
                }),
        );
    }

    fn check_uniform(&mut self, id: UniformId, d: &UniformDecl) {
        for attr in &d.attrs {
            self.unknown_attribute(attr, &attr.name.name.clone(), &[]);
        }
        let mut ty = self.out.uniforms[id.index()].ty.clone();
        if matches!(ty, Type::AbstractFloat | Type::AbstractInt) {
            ty = Type::Error;
        }
        if let Some(len) = &d.array_len {
            let n = match self.const_eval(len) {
                Some(v)
                    if v.values.len() == 1
                        && v.values[0] >= 1.0
                        && v.values[0].fract() == 0.0
                        && v.values[0] <= 65536.0 =>
                {
                    v.values[0] as u32
                }
                _ => {
                    self.error(err(
                        "E0112",
                        "array length must be a positive integer constant",
                        len.span,
                        "not a constant length",
                    ));
                    1
                }
            };
            let sixteen = matches!(ty, Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, 4) | Type::Matrix(4));
            if !sixteen && !ty.is_error() {
                self.error(
                    err("E0113", format!("uniform arrays of `{ty}` are not supported"), d.ty.span, "element type")
                        .with_note("uniform array elements must be 16 bytes wide: use float4, int4, uint4 or float4x4"),
                );
            }
            ty = Type::Array(Box::new(ty), n);
            self.out.uniforms[id.index()].ty = ty.clone();
        }
        let texture = matches!(self.out.uniforms[id.index()].kind, UniformKind::Texture | UniformKind::Sampler);
        if let (Some(default), true) = (&d.default, texture) {
            self.error(err("E0114", "textures and samplers cannot have a default", default.span, "remove this"));
        } else if let Some(default) = &d.default
            && let Some(values) = self.uniform_default(default, &ty)
        {
            self.out.uniforms[id.index()].kind =
                UniformKind::Value { default: Some(ConstValue { ty: ty.clone(), values }) };
        }
        if let (Some(elements), Type::Array(element, n)) = (&d.elements, &ty)
            && !element.is_error()
        {
            if elements.items.len() != *n as usize {
                let k = elements.items.len();
                self.error(err(
                    "E0118",
                    format!("the default has {k} element{}, the array {n}", if k == 1 { "" } else { "s" }),
                    elements.span,
                    format!("{n} expected"),
                ));
                return;
            }
            let values: Vec<Option<Vec<f64>>> =
                elements.items.iter().map(|item| self.uniform_default(item, element)).collect();
            if values.iter().all(Option::is_some) {
                let values = values.into_iter().flatten().flatten().collect();
                self.out.uniforms[id.index()].kind =
                    UniformKind::Value { default: Some(ConstValue { ty: ty.clone(), values }) };
            }
        }
    }

    /// The components of a uniform's default (or of one element of an
    /// array's) of type `ty`: a constant expression (E0115) of that type
    /// (E0201) with values it holds (E0205).
    fn uniform_default(&mut self, default: &Expr, ty: &Type) -> Option<Vec<f64>> {
        match self.const_eval(default) {
            // `uniform uint u = -1;`, `uniform int i = 2147483647 + 1;`.
            Some(v) if (v.ty.converts_to(ty) || v.ty == *ty) && super::fold::misfit(ty, &v.values).is_some() => {
                let name = super::fold::misfit(ty, &v.values).unwrap_or("its type");
                self.error(err(
                    "E0205",
                    format!("uniform default out of range for `{name}`"),
                    default.span,
                    "out of range",
                ));
                None
            }
            Some(v) if v.ty.converts_to(ty) || v.ty == *ty => Some(v.values),
            Some(v) => {
                self.error(err(
                    "E0201",
                    format!("default value has type `{}`, but the uniform is `{ty}`", v.ty),
                    default.span,
                    "wrong type",
                ));
                None
            }
            None => {
                self.error(err(
                    "E0115",
                    "a uniform default must be a constant expression",
                    default.span,
                    "not constant",
                ));
                None
            }
        }
    }

    fn check_effect_decl(&mut self, id: EffectId, d: &EffectDecl) {
        let ty = self.out.effects[id.index()].ty.clone();
        let ok = match d.rate {
            Rate::Out => matches!(
                ty,
                Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                    | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
            ),
            _ => ty.is_value(),
        };
        if !ok && !ty.is_error() {
            let what = if d.rate == Rate::Out { "an output" } else { "an effect" };
            self.error(
                err("E0104", format!("{what} cannot have type `{ty}`"), d.ty.span, "unsupported type").with_note(
                    if d.rate == Rate::Out {
                        "outputs are scalars or vectors of float, int or uint"
                    } else {
                        "effects are scalars, vectors or matrices"
                    },
                ),
            );
        }
        if let Some((n, span)) = d.coarse_block
            && !COARSE_BLOCKS.iter().any(|&b| u64::from(b) == n)
        {
            self.error(
                err("E0117", format!("there is no coarse rate of {n}x{n} blocks"), span, "expected 4 or 2")
                    .with_note("`coarse(4)` shades one sample per 4x4 block, `coarse(2)` one per 2x2 block; plain `coarse` takes the mode's block size"),
            );
        }
        for attr in &d.attrs {
            match (attr.name.name.as_str(), d.rate) {
                ("nearest", Rate::Coarse) if !attr.args.is_empty() => {
                    self.error(err("E0110", "`@nearest` takes no arguments", attr.span, "remove the arguments"))
                }
                ("nearest", Rate::Coarse) => self.out.effects[id.index()].nearest = true,
                ("format", Rate::Out) => {
                    let format = match attr.args.as_slice() {
                        [Expr { kind: ExprKind::Name(n), .. }] => Some(n.clone()),
                        _ => None,
                    };
                    match format {
                        Some(f) if let Some(fits) = output_format_fits(&f, &ty) => {
                            self.out.effects[id.index()].format = Some(fits)
                        }
                        Some(f) => self.error(
                            err(
                                "E0116",
                                format!("format `{f}` cannot store a `{ty}` output"),
                                attr.span,
                                "unsupported format",
                            )
                            .with_note(format!(
                                "formats for `{ty}`: {}",
                                formats_for(&ty).iter().map(|f| f.name()).collect::<Vec<_>>().join(", ")
                            )),
                        ),
                        None => self.error(err(
                            "E0116",
                            "`@format` takes one format name, e.g. `@format(rgba8unorm)`",
                            attr.span,
                            "expected a format name",
                        )),
                    }
                }
                (other, Rate::Coarse) => {
                    self.unknown_attribute(attr, other, &attributes::names_on(Target::CoarseEffect))
                }
                (other, Rate::Out) => self.unknown_attribute(attr, other, &attributes::names_on(Target::Output)),
                (other, Rate::Fine) => self.unknown_attribute(attr, other, &[]),
            }
        }
        if d.rate == Rate::Out && self.out.effects[id.index()].format.is_none() && ok {
            self.out.effects[id.index()].format = Some(default_output_format(&ty));
        }
    }
}

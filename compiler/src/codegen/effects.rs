//! What every kernel declares before its entry points: the bindings, the
//! position helpers and input loaders, one `mrsl_eval_<effect>` function per
//! effect, the derivative helpers and the `mrsl_at_<effect>` functions that
//! give an effect's value at another position; and how an effect is
//! evaluated in a chain, and how discontinuity keys are compared, which the
//! entry points of every family use.

use super::body::{Mode, float_literal, local_name, wgsl_ident};
use super::names::{
    BACKGROUND, BACKGROUND_PIXEL, BLOCK_SIZE, CONTROL, FORCE, HERE, IN_BACKGROUND_TILE, LEVEL, Name, OCTAHEDRAL,
    PAIR_X, PAIR_Y, POS, REFINE, RGB9E5,
};
use super::words::bit;
use super::writer::cut;
use super::{Derivatives, Writer};
use crate::check::{Background, EffectId, InputId, KeyCompare, Symbol};
use crate::syntax::ast::*;
use crate::syntax::{visit_expr, visit_stmt_exprs};
use crate::types::Scalar;
use mrsl_abi::{BevyField, CONTROL_FIELDS, ChannelAccess, Decode, KernelKind, SampleType};
use std::collections::{BTreeSet, HashMap, HashSet};

/// The most parameters a WGSL function may declare (the specification's
/// limit, which Tint enforces and naga does not).
const MAX_PARAMETERS: usize = 255;

/// The members of one structure of packed dependencies: within WGSL's
/// limit of 1023 members per structure.
const ARGS_PER_STRUCT: usize = 1000;

/// A discontinuity key: an input that, where its values at two positions
/// differ, keeps them from sharing coarse values. A channel with a
/// background rule is a key too: the background and what was drawn never
/// share coarse values.
pub(super) struct Key<'c> {
    pub(super) name: &'c str,
    /// The WGSL type of the key's value at a position ([`Key::load`]): the
    /// channel's type, or for a surface key the position and normal together.
    pub(super) ty: String,
    compare: Option<KeyCompare>,
    background: Option<Background>,
    scalar: Scalar,
    components: u32,
}

impl Key<'_> {
    /// WGSL that is true where the key's values `a` and `b` differ: an
    /// operand of `||` (a call, or parenthesised).
    pub(super) fn differs(&self, a: &str, b: &str) -> String {
        self.compare(a, b, true)
    }

    /// WGSL that is true where `a` and `b` match: a bare comparison, which
    /// the caller parenthesises.
    pub(super) fn matches(&self, a: &str, b: &str) -> String {
        self.compare(a, b, false)
    }

    /// The function that gives the key's value at a position: the
    /// channel's loader, or a surface key's (position and normal together).
    pub(super) fn loader(&self) -> String {
        match self.compare {
            Some(KeyCompare::Surface { .. }) => Name::SurfaceKey.of(self.name),
            _ => Name::Load.of(self.name),
        }
    }

    /// The key's value at `pos`.
    pub(super) fn load(&self, pos: &str) -> String {
        format!("{}({pos})", self.loader())
    }

    /// The one comparison of key values: exact (`any` over vector
    /// components), by distance against the key's threshold, or against
    /// the surface; and, for a background channel, whether one value is
    /// background and the other not. In either sense.
    fn compare(&self, a: &str, b: &str, differs: bool) -> String {
        let (equal, reduce, close) = if differs { ("!=", "any", ">") } else { ("==", "all", "<=") };
        // Each test, and whether it is a call (an operand of `||` as it stands).
        let mut tests: Vec<(String, bool)> = vec![];
        match &self.compare {
            None => {}
            Some(KeyCompare::Exact) if self.components == 1 => tests.push((format!("{a} {equal} {b}"), false)),
            Some(KeyCompare::Exact) => tests.push((format!("{reduce}({a} {equal} {b})"), true)),
            Some(KeyCompare::Threshold { threshold }) => {
                tests.push((format!("distance({a}, {b}) {close} {}", float_literal(*threshold)), false))
            }
            Some(KeyCompare::Surface { .. }) => {
                let edge = format!("{}({a}, {b})", Name::SurfaceEdge.of(self.name));
                tests.push(if differs { (edge, true) } else { (format!("!{edge}"), true) })
            }
        }
        if let Some(rule) = self.background {
            let (a, b) = (self.is_background(rule, a), self.is_background(rule, b));
            tests.push((format!("{a} {equal} {b}"), false));
        }
        match (tests.as_slice(), differs) {
            ([(one, call)], true) if *call => one.clone(),
            ([(one, _)], true) => format!("({one})"),
            ([(one, _)], false) => one.clone(),
            (_, true) => format!("({})", tests.iter().map(|(t, _)| t.as_str()).collect::<Vec<_>>().join(" || ")),
            (_, false) => tests.iter().map(|(t, _)| format!("({t})")).collect::<Vec<_>>().join(" && "),
        }
    }

    /// Whether the channel says the pixel at `pos` is background.
    pub(super) fn background_at(&self, pos: &str) -> String {
        let rule = self.background.expect("a background channel");
        self.is_background(rule, &format!("{}({pos})", Name::Load.of(self.name)))
    }

    /// `(value == V)`, or `(value != V)` for `@foreground(V)`.
    fn is_background(&self, rule: Background, value: &str) -> String {
        let (op, v) = match rule {
            Background::Equal { value } => ("==", value),
            Background::NotEqual { value } => ("!=", value),
        };
        format!("({value} {op} {})", self.literal(v))
    }

    /// `v` as a WGSL value of the channel's scalar type.
    fn literal(&self, v: f64) -> String {
        match self.scalar {
            Scalar::Uint => format!("{}u", v as u64),
            Scalar::Int => format!("i32({})", v as i64),
            _ => float_literal(v),
        }
    }

    /// The channel's value wherever its rule says background, where that is
    /// one value to the bit: `@background(V)` on an integer channel, or on a
    /// float one with `V` not zero (`-0.0 == 0.0`, and the two differ in
    /// what a program can compute from them). `None` for `@foreground`.
    fn value_where_background(&self) -> Option<String> {
        match self.background? {
            Background::Equal { value } if self.scalar != Scalar::Float || value != 0.0 => Some(self.literal(value)),
            _ => None,
        }
    }
}

/// What an evaluation does with the refine flags of the effects it evaluates.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Evaluation {
    /// What the kernel does: an effect that can refine sets its flag where
    /// the kernel reads them ([`Writer::keeps_refine_flags`]), and is
    /// evaluated for its value alone (`mrsl_val_<effect>`) where it does not.
    Kernel,
    /// For the value alone, the flags discarded: the neighbour evaluations
    /// (`mrsl_at_<effect>`, `coarse_neighbours`).
    ValueOnly,
}

impl<'b> Writer<'_, '_, 'b> {
    /// The discontinuity keys that concern any of `effects` (those they read,
    /// directly or through other effects: `EffectGraph::keys`), in
    /// declaration order. A key no coarse effect reads is never loaded.
    pub(super) fn keys_of(&self, effects: &[EffectId]) -> Vec<Key<'b>> {
        let read: BTreeSet<InputId> =
            effects.iter().flat_map(|e| self.i.graph.keys[e.index()].iter().copied()).collect();
        read.into_iter().map(|i| self.key(i)).collect()
    }

    /// The key of channel `i` (a discontinuity key, a background channel or both).
    fn key(&self, i: InputId) -> Key<'b> {
        let x = &self.checked().inputs[i.index()];
        let ty = match x.key {
            Some(KeyCompare::Surface { .. }) => Name::SurfaceStruct.of(&x.name),
            _ => x.ty.wgsl(),
        };
        Key {
            name: &x.name,
            ty,
            compare: x.key.clone(),
            background: x.background,
            scalar: x.ty.scalar().unwrap_or(Scalar::Float),
            components: x.ty.components(),
        }
    }

    /// `disc || disc_<key>...`: true where effect `e` is refined by a
    /// discontinuity: `disc` (forced refinement and what the kernel adds)
    /// or one of the keys `e` reads, each tested into `disc_<key>`.
    pub(super) fn discontinuity(&self, e: EffectId) -> String {
        let c = self.checked();
        let mut terms = vec!["disc".to_string()];
        terms.extend(self.i.graph.keys[e.index()].iter().map(|i| format!("disc_{}", c.inputs[i.index()].name)));
        terms.join(" || ")
    }

    /// Every binding the kernel uses, where the layout puts it: the control
    /// block, user uniforms, textures and samplers, the G-buffer channels,
    /// then the stage's buffers (per kernel family), statistics and outputs.
    pub(super) fn bindings(&mut self) {
        let l = self.i.layout;
        let [control, user, channels, stage, end] =
            cut(include_str!("templates/resources.wgsl"), &["CONTROL_FIELDS", "USER_RESOURCES", "CHANNELS", "STAGE"]);
        self.template(0, control, &[]);
        for f in &CONTROL_FIELDS {
            match f.comment {
                Some(comment) => self.line(1, format!("{}: {}, // {comment}", f.name, f.wgsl_type)),
                None => self.line(1, format!("{}: {},", f.name, f.wgsl_type)),
            }
        }
        self.template(0, user, &[("GROUP", &l.control.group), ("BINDING", &l.control.binding)]);
        if let Some(u) = &l.uniforms {
            let [head, tail] = cut(include_str!("templates/uniforms.wgsl"), &["FIELDS"]);
            self.template(0, head, &[]);
            for f in &u.fields {
                self.line(1, format!("{}: {}, // offset {}", wgsl_ident(&f.name), f.wgsl_type, f.offset));
            }
            self.template(0, tail, &[("GROUP", &u.group), ("BINDING", &u.binding)]);
        }
        for t in &l.textures {
            self.line(
                0,
                format!("@group({}) @binding({}) var {}: texture_2d<f32>;", t.group, t.binding, wgsl_ident(&t.name)),
            );
        }
        for s in &l.samplers {
            self.line(0, format!("@group({}) @binding({}) var {}: sampler;", s.group, s.binding, wgsl_ident(&s.name)));
        }
        self.template(0, channels, &[]);
        for ch in &l.channels {
            let texture = match (ch.access, ch.sample_type) {
                (ChannelAccess::Storage, _) => format!("texture_storage_2d<{}, read>", ch.format),
                (ChannelAccess::Sampled, SampleType::Depth) => "texture_depth_2d".to_string(),
                (ChannelAccess::Sampled, _) => format!("texture_2d<{}>", ch.format.scalar().wgsl()),
            };
            let (group, binding, name) = (ch.group, ch.binding, Name::GBuffer.of(&ch.name));
            self.line(0, format!("@group({group}) @binding({binding}) var {name}: {texture}; // {}", ch.format));
        }
        self.template(0, stage, &[]);
        if self.file == KernelKind::Tile {
            // Its stage group is declared from the plan's bindings.
            self.tile_stage_group();
            return self.template(0, end, &[]);
        }
        match self.kind {
            // (The multi-rate kernels are written as the block kernels of their family.)
            KernelKind::Coarse
            | KernelKind::Fine
            | KernelKind::DynamicFine
            | KernelKind::MultiCoarse
            | KernelKind::MultiResolve
            | KernelKind::MultiFine => self.interface_bindings(),
            KernelKind::Tile => unreachable!("the tile kernel is written by the fine family's writer"),
            KernelKind::DynamicCoarse => self.dynamic_coarse_bindings(),
            KernelKind::Hierarchical => self.hierarchical_bindings(),
            KernelKind::Checkerboard => self.checkerboard_bindings(),
            KernelKind::RateCoarse | KernelKind::RateFine => self.rate_bindings(),
            KernelKind::Reference => {}
        }
        if self.counts_stats() {
            self.stats_bindings();
        } else if self.counts_background_samples() {
            // The coarse kernels count the background samples.
            self.stats_buffer();
        }
        if self.file.writes_outputs() {
            for o in &l.outputs {
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var {}: texture_storage_2d<{}, write>;",
                        o.group,
                        o.binding,
                        Name::Out.of(&o.name),
                        o.format
                    ),
                );
            }
        }
        self.template(0, end, &[]);
    }

    /// `mrsl_grid` (the positions of this kernel), `mrsl_pixel` (where a
    /// position loads its inputs) and `mrsl_pair_x` / `mrsl_pair_y` (a
    /// position's quad, which derivatives difference across).
    pub(super) fn position_helpers(&mut self) {
        if self.kind == KernelKind::RateCoarse {
            // Its samples are pixels, listed by its tiles; derivatives pair cells of the tile's rate.
            return self.template(0, include_str!("templates/rate_positions.wgsl"), &[]);
        }
        let (grid, pixel) = if self.kind.is_coarse() {
            (
                format!("(size + vec2<i32>({BLOCK_SIZE} - 2)) / {BLOCK_SIZE} + vec2<i32>(1)"),
                format!("min(pos * {BLOCK_SIZE}, vec2<i32>({CONTROL}.size) - vec2<i32>(1))"),
            )
        } else {
            ("size".to_string(), "pos".to_string())
        };
        self.template(0, include_str!("templates/positions.wgsl"), &[("GRID", &grid), ("PIXEL", &pixel)]);
    }

    /// `mrsl_load_<input>(pos)`: a G-buffer channel at a position's pixel,
    /// decoded where the engine stores it encoded (`@depth`, `@encoded`):
    /// every kernel reads a channel through its loader, so all decode alike.
    pub(super) fn input_loaders(&mut self) {
        let c = self.checked();
        let inputs = &c.inputs;
        let known = self.known_background();
        if known.is_some() {
            self.line(0, "// Set by the entry points over background tiles, where the background rule holds at");
            self.line(0, "// every pixel: the pixel about to be shaded, where the background channel's loader");
            self.line(0, "// returns the rule's value without a load. Every other entry point leaves the flag");
            self.line(0, "// false, so the test folds away there.");
            self.line(0, format!("var<private> {IN_BACKGROUND_TILE}: bool;"));
            self.line(0, format!("var<private> {BACKGROUND_PIXEL}: vec2<i32>;"));
            self.line(0, "");
        }
        let bevy = |f: BevyField| Some(Decode::BevyDeferred { field: f });
        let octahedral = |d: &Option<Decode>| {
            matches!(d, Some(Decode::Octahedral | Decode::OctahedralUnorm)) || *d == bevy(BevyField::Normal)
        };
        if inputs.iter().any(|i| octahedral(&i.decode)) {
            self.template(0, include_str!("templates/octahedral.wgsl"), &[]);
        }
        if inputs.iter().any(|i| i.decode == bevy(BevyField::Emissive)) {
            self.template(0, include_str!("templates/rgb9e5.wgsl"), &[]);
        }
        for (k, (input, channel)) in inputs.iter().zip(&self.i.layout.channels).enumerate() {
            // A storage texture has no mip level to name.
            let level = match channel.access {
                ChannelAccess::Sampled => ", 0",
                ChannelAccess::Storage => "",
            };
            let swizzle = match input.ty.components() {
                1 => ".x",
                2 => ".xy",
                3 => ".xyz",
                _ => "",
            };
            let name = &input.name;
            let known = known.as_ref().filter(|(i, _)| i.index() == k).map(|(_, v)| v.as_str());
            match &input.decode {
                None => self.loader(
                    include_str!("templates/load.wgsl"),
                    &[("NAME", name), ("TYPE", &input.ty.wgsl()), ("SWIZZLE", &swizzle), ("LEVEL", &level)],
                    known,
                ),
                Some(Decode::Unorm) => {
                    let swizzle = format!("{swizzle} * 2.0 - 1.0");
                    self.loader(
                        include_str!("templates/load.wgsl"),
                        &[("NAME", name), ("TYPE", &input.ty.wgsl()), ("SWIZZLE", &swizzle), ("LEVEL", &level)],
                        known,
                    )
                }
                Some(Decode::Depth { inverse_view_projection }) => self.template(
                    0,
                    include_str!("templates/load_depth.wgsl"),
                    &[("NAME", name), ("MATRIX", &wgsl_ident(inverse_view_projection))],
                ),
                Some(Decode::BevyDeferred { field }) => {
                    let what = BevyField::ALL.iter().find(|(f, ..)| f == field).map_or("", |(_, n, _)| n);
                    let value = bevy_field(*field);
                    let values: [(&str, &dyn std::fmt::Display); 5] = [
                        ("NAME", name),
                        ("FIELD", &what),
                        ("TYPE", &input.ty.wgsl()),
                        ("VALUE", &value),
                        ("LEVEL", &level),
                    ];
                    self.loader(include_str!("templates/load_packed.wgsl"), &values, known)
                }
                Some(octahedral) => {
                    let unorm = if *octahedral == Decode::OctahedralUnorm { " * 2.0 - 1.0" } else { "" };
                    self.template(
                        0,
                        include_str!("templates/load_octahedral.wgsl"),
                        &[("NAME", name), ("UNORM", &unorm), ("LEVEL", &level)],
                    )
                }
            }
        }
    }

    /// A loader template with its `KNOWN` hole filled: where `known` is the
    /// channel's value at every pixel of a background tile, the loader returns
    /// it at the pixel an entry point over those tiles shades.
    fn loader(&mut self, template: &str, values: &super::writer::Values, known: Option<&str>) {
        let [head, tail] = cut(template, &["KNOWN"]);
        self.template(0, head, values);
        if let Some(value) = known {
            let here = format!("{IN_BACKGROUND_TILE} && all(pos == {BACKGROUND_PIXEL})");
            self.line(1, format!("if ({here}) {{ return {value}; }}"));
        }
        self.template(0, tail, values);
    }

    /// Whether the kernel has an entry point over background tiles (the
    /// per-pixel passes' `fine_background`, the hierarchical kernel's
    /// `hier_background`): every pixel it shades is background.
    fn shades_background_tiles(&self) -> bool {
        self.lists_tiles() || (self.file == KernelKind::Hierarchical && self.has_background())
    }

    /// The background channel and its value (WGSL) at every pixel of a
    /// background tile, in a kernel with entry points over such tiles: where
    /// the program's one background rule is `@background(V)` and `V` is one
    /// value to the bit. Those entry points then evaluate the fine effects and
    /// outputs with the value, not a load, so that what the program computes
    /// only for drawn pixels (`material == 255u ? sky : lit`) folds away
    /// there. With several rules a background pixel does not say which
    /// channel holds its value.
    pub(super) fn known_background(&self) -> Option<(InputId, String)> {
        if !self.shades_background_tiles() {
            return None;
        }
        let c = self.checked();
        let mut rules = (0..c.inputs.len() as u32).map(InputId).filter(|i| c.inputs[i.index()].background.is_some());
        match (rules.next(), rules.next()) {
            (Some(i), None) => self.key(i).value_where_background().map(|v| (i, v)),
            _ => None,
        }
    }

    /// In an entry point over background tiles, before pixel `pos` is
    /// shaded: the background channel's loader returns its value there.
    pub(super) fn background_known_at(&mut self, indent: usize, pos: &str) {
        if self.known_background().is_some() {
            self.line(indent, format!("{IN_BACKGROUND_TILE} = true;"));
            self.line(indent, format!("{BACKGROUND_PIXEL} = {pos};"));
        }
    }

    /// For every surface key, its value (`MrslSurface_<channel>`: the
    /// position and its normal), the function that loads it and the
    /// function that tests two of them for an edge; and `mrsl_background`
    /// where the program has a background rule.
    pub(super) fn key_functions(&mut self) {
        let c = self.checked();
        for input in &c.inputs {
            let Some(KeyCompare::Surface { normal, threshold }) = &input.key else { continue };
            let (ty, load) = (Name::SurfaceStruct.of(&input.name), Name::Load.of(&input.name));
            self.template(
                0,
                include_str!("templates/surface_key.wgsl"),
                &[
                    ("NAME", &input.name),
                    ("TYPE", &ty),
                    ("KEY", &Name::SurfaceKey.of(&input.name)),
                    ("EDGE", &Name::SurfaceEdge.of(&input.name)),
                    ("LOAD_POSITION", &load),
                    ("LOAD_NORMAL", &Name::Load.of(normal)),
                    ("THRESHOLD", &float_literal(*threshold)),
                ],
            );
        }
        let tests: Vec<String> = (0..c.inputs.len() as u32)
            .map(InputId)
            .filter(|i| c.inputs[i.index()].background.is_some())
            .map(|i| {
                let key = self.key(i);
                key.background_at("pos")
            })
            .collect();
        if !tests.is_empty() {
            self.template(0, include_str!("templates/background.wgsl"), &[("TESTS", &tests.join(" || "))]);
        }
    }

    /// WGSL: the background rule holds at `pos` and refinement is not forced
    /// (forced, a background pixel is evaluated, and reads as zero).
    pub(super) fn background_here(&self, pos: &str) -> String {
        format!("({BACKGROUND}({pos}) && {CONTROL}.force_refine == 0u)")
    }

    /// Whether the program has a background rule (`@background`, `@foreground`).
    pub(super) fn has_background(&self) -> bool {
        self.checked().inputs.iter().any(|i| i.background.is_some())
    }

    pub(super) fn deps_params(&self, e: EffectId) -> Vec<EffectId> {
        self.checked().effects[e.index()].deps.iter().map(|(d, _)| *d).collect()
    }

    /// The dependencies of `e` in the parts its functions take them in: one
    /// parameter each (one part of one), or, where that would pass more
    /// parameters than WGSL allows, packed into structures of at most
    /// [`ARGS_PER_STRUCT`] members ([`Self::args_structs`]).
    fn dependency_parts(&self, e: EffectId) -> Option<Vec<Vec<EffectId>>> {
        let deps = self.deps_params(e);
        // The position and the refine flag come first.
        (deps.len() + 2 > MAX_PARAMETERS).then(|| deps.chunks(ARGS_PER_STRUCT).map(<[EffectId]>::to_vec).collect())
    }

    /// `MrslArgs<k>_<effect>` of every effect this kernel evaluates whose
    /// dependencies are too many to pass one parameter each.
    pub(super) fn args_structs(&mut self) {
        let c = self.checked();
        for e in self.kernel_effects() {
            let Some(parts) = self.dependency_parts(e) else { continue };
            let name = &c.effects[e.index()].name;
            self.line(0, format!("// `{name}` reads more effects than a function may take parameters"));
            for (k, part) in parts.iter().enumerate() {
                self.line(0, format!("struct {} {{", Name::Args.within(k, name)));
                for &d in part {
                    self.line(1, format!("{}: {},", self.effect_name(d), c.effects[d.index()].ty.wgsl()));
                }
                self.line(0, "}");
            }
            self.line(0, "");
        }
    }

    /// The signature of `mrsl_eval_<effect>`, or of `mrsl_val_<effect>`
    /// (`value_only`), which has no refine flag.
    pub(super) fn eval_signature(&self, e: EffectId, value_only: bool) -> String {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let mut params = vec![format!("{POS}: vec2<i32>")];
        if info.has_refine && !value_only {
            params.push(format!("{REFINE}: ptr<function, bool>"));
        }
        match self.dependency_parts(e) {
            None => {
                for d in self.deps_params(e) {
                    params.push(format!("{}: {}", self.effect_name(d), c.effects[d.index()].ty.wgsl()));
                }
            }
            Some(parts) => {
                for k in 0..parts.len() {
                    params.push(format!("{}: {}", Name::ArgsParam.of(k), Name::Args.within(k, &info.name)));
                }
            }
        }
        let function = if value_only { Name::Val } else { Name::Eval };
        format!("fn {}({}) -> {}", function.of(&info.name), params.join(", "), info.ty.wgsl())
    }

    /// Inputs an effect body reads directly, outside the statements in
    /// `skipped` (those a value-only function leaves out).
    fn inputs_read(&self, decl: &EffectDecl, skipped: Option<&HashSet<NodeId>>) -> BTreeSet<usize> {
        let c = self.checked();
        let mut read = BTreeSet::new();
        let mut visit = |e: &Expr| {
            visit_expr(e, &mut |x| {
                if let Some(Symbol::Input(i)) = c.symbols.get(&x.id) {
                    read.insert(i.index());
                }
            })
        };
        match &decl.body {
            EffectBody::Expr(e) => visit(e),
            EffectBody::Block(b) => match skipped {
                None => b.stmts.iter().for_each(|s| visit_stmt_exprs(s, &mut visit)),
                Some(skipped) => b.stmts.iter().for_each(|s| visit_kept_exprs(s, skipped, &mut visit)),
            },
        }
        read
    }

    /// Whether coarse effect `e`'s value, not only its refine decision,
    /// reads a derivative (or a `sample`, whose gradients are derivatives),
    /// directly or through the coarse effects it reads. Its value at a
    /// coarse sample then depends on the sample's quad neighbour, which may
    /// lie across an edge, so the fine kernel never resamples it from the
    /// corners on one side of an edge ([`Writer::edge_discontinuity`]).
    pub(super) fn value_reads_derivatives(&self, e: EffectId) -> bool {
        // In dependency order, each effect once: a recursion over the
        // dependencies would revisit shared ones (exponentially many times
        // in a lattice of diamonds).
        let c = self.checked();
        let mut reads = vec![false; c.effects.len()];
        for &x in &self.i.graph.order {
            if c.effects[x.index()].rate != Rate::Coarse {
                continue;
            }
            reads[x.index()] =
                self.own_value_reads_derivatives(x) || c.effects[x.index()].deps.iter().any(|(d, _)| reads[d.index()]);
            if x == e {
                break;
            }
        }
        reads[e.index()]
    }

    /// [`Self::value_reads_derivatives`] for `e`'s own body alone: a
    /// derivative call outside the statements that only decide its refine
    /// flag (`DerivInfo::value_skips`).
    fn own_value_reads_derivatives(&self, e: EffectId) -> bool {
        let c = self.checked();
        let own: Vec<NodeId> = c.derivative_calls.iter().filter(|(x, _)| *x == e).map(|(_, n)| *n).collect();
        if own.is_empty() {
            return false;
        }
        let kept = self.value_expressions(e);
        own.iter().any(|n| kept.contains(n))
    }

    /// The expressions of `e`'s body that its value needs: all but those in
    /// the statements that only decide its refine flag (`DerivInfo::value_skips`).
    fn value_expressions(&self, e: EffectId) -> HashSet<NodeId> {
        let c = self.checked();
        let mut kept = HashSet::new();
        let mut collect = |x: &Expr| visit_expr(x, &mut |y| _ = kept.insert(y.id));
        match &c.effect_decl(e).body {
            EffectBody::Expr(x) => collect(x),
            EffectBody::Block(b) => {
                let none = HashSet::new();
                let skipped = self.i.deriv.value_skips.get(&e).unwrap_or(&none);
                b.stmts.iter().for_each(|s| visit_kept_exprs(s, skipped, &mut collect));
            }
        }
        kept
    }

    /// Whether derivative site `k` is taken from the level's neighbours at
    /// hierarchical levels 1 to 3 ([`Derivatives::HereOrLevelNeighbours`]):
    /// its operand reads a coarse effect, which the quad pair would evaluate
    /// at the partner, and it only decides a refine flag (a predicate's
    /// derivative), so the values, and forced refinement, never depend on it.
    pub(super) fn takes_level_differences(&self, k: usize) -> bool {
        let site = &self.i.deriv.sites[k];
        if self.derivatives() != Derivatives::HereOrLevelNeighbours || site.effects.is_empty() {
            return false;
        }
        !self.value_expressions(site.effect).contains(&site.node)
    }

    /// Whether derivative site `k` is taken from the level's neighbours at
    /// every level that evaluates predicates, level 0 included (where the
    /// hierarchical kernel stores its neighbours' values first): then no
    /// quad pair is left, and the operand is never evaluated elsewhere.
    pub(super) fn only_level_differences(&self, k: usize) -> bool {
        self.stores_level0_values() && self.takes_level_differences(k)
    }

    /// `mrsl_eval_<effect>`: the effect's body at `mrsl_pos`, given its
    /// dependencies' values (and a refine flag to set, if it can refine).
    /// With `value_only`, `mrsl_val_<effect>` of an effect that can refine:
    /// the same value, without the statements that only decide the refine
    /// flag (`DerivInfo::value_skips`), for evaluations that discard it.
    pub(super) fn eval_function(&mut self, e: EffectId, value_only: bool) {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let decl = c.effect_decl(e);
        // The statements a value-only function leaves out.
        let skipped = if value_only { self.i.deriv.value_skips.get(&e) } else { None };
        if value_only {
            self.line(
                0,
                format!("// `{}`'s value alone, without the statements that only decide its refine flag", info.name),
            );
        } else {
            let rate = match info.rate {
                Rate::Coarse => "coarse effect",
                Rate::Fine => "fine effect",
                Rate::Out => "fine out",
            };
            self.line(0, format!("// ---- {rate} `{}` ----", info.name));
        }
        let sig = self.eval_signature(e, value_only);
        self.line(0, format!("{sig} {{"));
        if info.rate == Rate::Coarse && self.has_background() {
            // The background rule: a coarse effect reads as zero where nothing was drawn.
            self.line(1, format!("if ({BACKGROUND}({POS})) {{ return {}(); }}", info.ty.wgsl()));
        }
        for (k, part) in self.dependency_parts(e).unwrap_or_default().iter().enumerate() {
            for &d in part {
                let dep = self.effect_name(d);
                self.line(1, format!("let {dep} = {}.{dep};", Name::ArgsParam.of(k)));
            }
        }
        for i in self.inputs_read(decl, skipped) {
            let name = &c.inputs[i].name;
            self.line(1, format!("let {} = {}({POS});", wgsl_ident(name), Name::Load.of(name)));
        }
        match &decl.body {
            EffectBody::Expr(x) => {
                let v = self.expr(x, Mode::Body);
                self.line(1, format!("return {v};"));
            }
            EffectBody::Block(b) => {
                let result = info.result.expect("block effects have a result local");
                let name = local_name(c, result);
                self.line(1, format!("var {name}: {};", info.ty.wgsl()));
                self.line(1, "{");
                for s in &b.stmts {
                    self.stmt(s, 2, skipped);
                }
                self.line(1, "}");
                self.line(1, format!("return {name};"));
            }
        }
        self.line(0, "}");
        self.line(0, "");
    }

    // ---- Derivatives and values at other positions ------------------------------

    /// The live derivative sites taken from the levels' neighbours
    /// ([`Self::takes_level_differences`]).
    pub(super) fn level_sites(&self) -> Vec<usize> {
        self.live_sites().into_iter().filter(|&k| self.takes_level_differences(k)).collect()
    }

    fn live_sites(&self) -> Vec<usize> {
        let mut computed = vec![false; self.checked().effects.len()];
        // A loaded effect's derivatives were taken where the resolve pass evaluated it.
        for e in self.kernel_effects().into_iter().filter(|&e| !self.is_loaded(e)) {
            computed[e.index()] = true;
        }
        (0..self.i.deriv.sites.len()).filter(|&k| computed[self.i.deriv.sites[k].effect.index()]).collect()
    }

    /// `mrsl_d<k>` (the operand of derivative site k at a position) and its
    /// differences across the position's quad, `mrsl_ddx_<k>` and `mrsl_ddy_<k>`.
    pub(super) fn derivative_helpers(&mut self) {
        let sites = self.live_sites();
        let mut apart: Vec<EffectId> =
            sites.iter().filter(|&&k| self.stays_on_surface(k)).map(|&k| self.i.deriv.sites[k].effect).collect();
        apart.sort();
        apart.dedup();
        for e in apart {
            self.apart_function(e);
        }
        for k in sites {
            self.cached(super::Piece::Derivative(k, self.derivatives()), |w| w.derivative_helper(k));
        }
    }

    /// Whether derivative site `k` takes its differences on the effect's
    /// surface in this kernel: a surface derivative, in a kernel over coarse
    /// samples, in an effect that reads a discontinuity key.
    fn stays_on_surface(&self, k: usize) -> bool {
        let site = &self.i.deriv.sites[k];
        site.builtin.on_surface()
            && self.derivatives() == Derivatives::HereOnSurface
            && !self.keys_of(&[site.effect]).is_empty()
    }

    /// `mrsl_apart_<effect>(a, b)`: whether positions `a` and `b` lie across
    /// one of the keys `effect` reads, as the resolve compares a pixel with a
    /// corner.
    fn apart_function(&mut self, effect: EffectId) {
        let keys = self.keys_of(&[effect]);
        let tests: Vec<String> = keys.iter().map(|key| key.differs(&key.load("a"), &key.load("b"))).collect();
        let name = Name::Apart.of(&self.checked().effects[effect.index()].name);
        self.line(0, format!("fn {name}(a: vec2<i32>, b: vec2<i32>) -> bool {{"));
        self.line(1, format!("return {};", tests.join(" || ")));
        self.line(0, "}");
        self.line(0, "");
    }

    fn derivative_helper(&mut self, k: usize) {
        let c = self.checked();
        {
            let site = &self.i.deriv.sites[k];
            // A derivative is a float (of the operand's shape): a literal
            // operand (`ddx(1)`) is a float, not the `int` it would concretize to.
            let ty = match c.ty(site.operand) {
                t if t.is_abstract() => crate::types::FLOAT,
                t => t.clone(),
            };
            let mut params = vec![format!("{POS}: vec2<i32>")];
            params.extend(
                site.params.iter().map(|p| format!("{}: {}", local_name(c, *p), c.locals[p.index()].ty.wgsl())),
            );
            let args: String = site.params.iter().map(|p| format!(", {}", local_name(c, *p))).collect();
            let text = crate::syntax::format::expression(&self.i.source[site.operand.span.range()]);
            if site.prefix.is_some() {
                self.prefix_function(k, &ty);
            }
            let operand = self.operand_at_neighbour(k, Mode::Neighbour(site));
            let values: &super::writer::Values = &[
                ("SITE", &k),
                ("EFFECT", &c.effects[site.effect.index()].name),
                ("TEXT", &text),
                ("PARAMS", &params.join(", ")),
                ("TYPE", &ty.wgsl()),
                ("OPERAND", &operand),
                ("ARGS", &args),
            ];
            let [operand_helper, ddx_head, ddx_rest, ddy_rest] =
                cut(include_str!("templates/derivative.wgsl"), &["DIFFERENCES", "LEVELS_X", "LEVELS_Y"]);
            let level_differences = |w: &mut Self| {
                let stored = w.operand_at_neighbour(k, Mode::Stored(site));
                let extra: &super::writer::Values = &[("STORED", &stored)];
                w.template(0, include_str!("templates/derivative_levels.wgsl"), &[values, extra].concat());
            };
            if self.only_level_differences(k) {
                // Every level that evaluates predicates takes them from its neighbours: no quad pair is left.
                level_differences(self);
                self.template(0, include_str!("templates/derivative_levels_only.wgsl"), values);
                return;
            }
            self.template(0, operand_helper, values);
            if self.stays_on_surface(k) {
                let apart = Name::Apart.of(&c.effects[site.effect.index()].name);
                let [note, difference] = cut(include_str!("templates/derivative_on_surface.wgsl"), &["AXIS"]);
                self.template(0, note, &[]);
                for (axis, difference_name, pair) in [("x", Name::Ddx.of(k), PAIR_X), ("y", Name::Ddy.of(k), PAIR_Y)] {
                    let extra: &super::writer::Values =
                        &[("APART", &apart), ("AXIS", &axis), ("DIFFERENCE", &difference_name), ("PAIR", &pair)];
                    self.template(0, difference, &[values, extra].concat());
                }
            } else if self.reuses_operand_here(k) {
                let levels = self.takes_level_differences(k);
                if levels {
                    level_differences(self);
                }
                // At levels 1 to 3 the level's neighbours give each difference, at level 0 the quad pair.
                let level_branch = |w: &mut Self, axis: usize| {
                    if levels {
                        w.line(1, format!("if ({LEVEL} != 0u) {{"));
                        w.line(2, format!("return {}({POS}{args}, {HERE})[{axis}];", Name::LevelDifferences.of(k)));
                        w.line(1, "}");
                    }
                };
                self.template(0, ddx_head, values);
                level_branch(self, 0);
                self.template(0, ddx_rest, values);
                level_branch(self, 1);
                self.template(0, ddy_rest, values);
            } else {
                self.template(0, include_str!("templates/derivative_both.wgsl"), values);
            }
        }
    }

    /// Derivative site `k`'s operand at another position `mrsl_pos` (WGSL),
    /// rebuilt as `mode` says: inlined, or for a site with a prefix
    /// ([`crate::deriv::DerivSite::prefix`]) its prefix function run there,
    /// given the effects it reads there.
    fn operand_at_neighbour(&self, k: usize, mode: Mode) -> String {
        let site = &self.i.deriv.sites[k];
        if site.prefix.is_none() {
            return self.expr(site.operand, mode);
        }
        let c = self.checked();
        let read = match mode {
            Mode::Stored(_) => Name::Stored,
            _ => Name::At,
        };
        let args: String =
            site.effects.iter().map(|e| format!(", {}({POS})", read.of(&c.effects[e.index()].name))).collect();
        format!("{}({POS}{args})", Name::Prefix.of(k))
    }

    /// `mrsl_prefix<k>`: the statements of the effect's body before
    /// derivative site `k` (its `refine`s left out) at position `mrsl_pos`,
    /// given the effects they read there, and the site's operand after them.
    fn prefix_function(&mut self, k: usize, ty: &crate::types::Type) {
        let c = self.checked();
        let site = &self.i.deriv.sites[k];
        let statement = site.prefix.expect("a site with a prefix");
        let info = &c.effects[site.effect.index()];
        let EffectBody::Block(b) = &c.effect_decl(site.effect).body else {
            unreachable!("prefixes are of block bodies")
        };
        let prefix = &b.stmts[..statement];
        let mut params = vec![format!("{POS}: vec2<i32>")];
        params.extend(
            site.effects.iter().map(|e| format!("{}: {}", self.effect_name(*e), c.effects[e.index()].ty.wgsl())),
        );
        let ordinal = statement + 1;
        self.line(
            0,
            format!(
                "// `{}`'s body before its statement {ordinal}, at another position, for derivative #{k}.",
                info.name
            ),
        );
        self.line(0, format!("fn {}({}) -> {} {{", Name::Prefix.of(k), params.join(", "), ty.wgsl()));
        let mut inputs = BTreeSet::new();
        let mut refines = HashSet::new();
        let mut visit = |e: &Expr| {
            visit_expr(e, &mut |x| {
                if let Some(Symbol::Input(i)) = c.symbols.get(&x.id) {
                    inputs.insert(i.index());
                }
            })
        };
        prefix.iter().for_each(|s| visit_stmt_exprs(s, &mut visit));
        visit(site.operand);
        prefix.iter().for_each(|s| refine_statements(s, &mut refines));
        for i in inputs {
            let name = &c.inputs[i].name;
            self.line(1, format!("let {} = {}({POS});", wgsl_ident(name), Name::Load.of(name)));
        }
        let result = info.result.expect("block effects have a result local");
        self.line(1, format!("var {}: {};", local_name(c, result), info.ty.wgsl()));
        for s in prefix {
            self.stmt(s, 1, Some(&refines));
        }
        self.line(1, format!("return {};", self.expr(site.operand, Mode::Body)));
        self.line(0, "}");
        self.line(0, "");
    }

    /// Whether derivative site `k`'s helpers take the operand's value at
    /// the position itself from the caller (`mrsl_here`) and evaluate only
    /// the pair's other position. That value equals what `mrsl_d<k>` would
    /// recompute there wherever the kernel's value of every effect at a
    /// position is what `mrsl_at_<effect>` computes there: in every kernel
    /// but the checkerboard's, whose pixels may hold a reconstructed value
    /// while its neighbour functions evaluate; there only an operand that
    /// reads no effect is taken from the caller. The hierarchical kernel
    /// takes the pixel's own value (evaluated, or interpolated where the
    /// pixel did not shade the effect) by definition (docs/language.md,
    /// section 9): it saves an evaluation of the effect per difference, and
    /// under forced refinement the value is the evaluated one.
    pub(super) fn reuses_operand_here(&self, k: usize) -> bool {
        match self.derivatives() {
            Derivatives::Here | Derivatives::HereOnSurface | Derivatives::HereOrLevelNeighbours => true,
            Derivatives::HereWithoutEffects => self.i.deriv.sites[k].effects.is_empty(),
        }
    }

    pub(super) fn derivatives(&self) -> Derivatives {
        match self.kind {
            KernelKind::Checkerboard => Derivatives::HereWithoutEffects,
            KernelKind::Hierarchical => Derivatives::HereOrLevelNeighbours,
            kind if kind.is_coarse() => Derivatives::HereOnSurface,
            _ => Derivatives::Here,
        }
    }

    /// Effects this kernel needs at other positions (for derivatives).
    fn effects_at_neighbours(&self) -> BTreeSet<EffectId> {
        let mut needed: BTreeSet<EffectId> = BTreeSet::new();
        for k in self.live_sites().into_iter().filter(|&k| !self.only_level_differences(k)) {
            let site = &self.i.deriv.sites[k];
            needed.extend(site.effects.iter().copied().filter(|e| self.i.graph.live[e.index()]));
        }
        needed
    }

    /// Whether the kernel reads the refine flags its evaluations set: the
    /// kernels that decide refinement (the coarse samples and the
    /// hierarchical levels). The per-pixel kernels (reference, fine, final
    /// passes) evaluate an effect where refinement is already decided, so
    /// its flag would be discarded: they evaluate values alone
    /// (`mrsl_val_<effect>`), without what only decides the flag, such as
    /// the derivatives in a predicate, which re-evaluate effects at the
    /// neighbours. The value is the same computation either way.
    pub(super) fn keeps_refine_flags(&self) -> bool {
        self.kind.is_coarse() || self.kind == KernelKind::Hierarchical
    }

    /// Effects with a refine flag that this kernel evaluates for their value
    /// alone (at the neighbours, or everywhere in a kernel that discards the
    /// flags), and so get a value-only function `mrsl_val_<effect>`.
    pub(super) fn value_only_effects(&self) -> BTreeSet<EffectId> {
        let c = self.checked();
        let mut effects = BTreeSet::new();
        // The hierarchical kernel's last level evaluates its coarse effects
        // for their values alone (`mrsl_shade_last`).
        if !self.keeps_refine_flags() || self.kind == KernelKind::Hierarchical {
            effects.extend(self.kernel_effects().into_iter().filter(|e| c.effects[e.index()].has_refine));
        }
        for e in self.effects_at_neighbours() {
            effects.extend(self.i.graph.closure(e, c).into_iter().filter(|x| c.effects[x.index()].has_refine));
        }
        effects
    }

    /// `mrsl_at_<effect>(pos)`: the effect's value at another position, as
    /// this kernel sees it there. Its refine flags are discarded, so effects
    /// are evaluated for their value alone.
    pub(super) fn neighbour_functions(&mut self) {
        let c = self.checked();
        if self.stores_neighbours() {
            for (e, _) in self.neighbour_values() {
                let info = &c.effects[e.index()];
                let by = if self.writes_coarse_part() { "the tile's first phase" } else { "`coarse_neighbours`" };
                self.line(0, format!("// `{}` at another sample, as {by} stored it there.", info.name));
                self.line(0, format!("fn {}({POS}: vec2<i32>) -> {} {{", Name::At.of(&info.name), info.ty.wgsl()));
                self.line(1, format!("return {};", self.neighbour_value(e, POS)));
                self.line(0, "}");
                self.line(0, "");
            }
            return;
        }
        let mut resolvers = HashMap::new();
        for e in self.effects_at_neighbours() {
            let info = &c.effects[e.index()];
            let chain = self.i.graph.closure(e, c);
            let coarse = chain.iter().any(|x| c.effects[x.index()].rate == Rate::Coarse);
            let resolver = if coarse && self.kind.is_fine() {
                self.neighbour_resolvers(e, &chain, &mut resolvers)
            } else {
                String::new()
            };
            self.line(
                0,
                format!(
                    "// `{}` at another position, as the {} kernel computes it there.",
                    info.name,
                    self.kind.name()
                ),
            );
            self.line(0, format!("fn {}({POS}: vec2<i32>) -> {} {{", Name::At.of(&info.name), info.ty.wgsl()));
            if coarse {
                self.resolve_preamble(1, &resolver);
            }
            self.effect_chain(&chain, 1, Evaluation::ValueOnly);
            self.line(1, format!("return {};", self.effect_name(e)));
            self.line(0, "}");
            self.line(0, "");
        }
    }

    // ---- Evaluating effects ----------------------------------------------------------

    /// Computes `effects` (in dependency order) into locals named after them:
    /// evaluated (as `how` says), except coarse effects in the fine kernels,
    /// which may be resampled.
    pub(super) fn effect_chain(&mut self, effects: &[EffectId], indent: usize, how: Evaluation) {
        let c = self.checked();
        for &e in effects {
            if self.kind.is_fine() && c.effects[e.index()].rate == Rate::Coarse {
                self.resolved_coarse_value(e, indent, how);
            } else {
                self.evaluate(e, indent, "let ", how);
            }
        }
    }

    /// Evaluates effect `e` at `mrsl_pos` into `{declare}{name}` (`declare`
    /// is `"let "`, or empty for a variable already declared), declaring its
    /// refine flag first if it has one and `how` keeps it ([`Evaluation`]).
    pub(super) fn evaluate(&mut self, e: EffectId, indent: usize, declare: &str, how: Evaluation) {
        self.evaluate_at(e, indent, declare, POS, "", how);
    }

    /// [`Self::evaluate`] at position `pos`, with the values of `e` and of
    /// its dependencies named `{prefix}{name}` (the block fine kernel's
    /// per-pixel values, `mrsl_v<k>_<effect>`).
    pub(super) fn evaluate_at(
        &mut self,
        e: EffectId,
        indent: usize,
        declare: &str,
        pos: &str,
        prefix: &str,
        how: Evaluation,
    ) {
        let info = &self.checked().effects[e.index()];
        let mut args = vec![pos.to_string()];
        let function = if info.has_refine && (how == Evaluation::ValueOnly || !self.keeps_refine_flags()) {
            Name::Val
        } else {
            if info.has_refine {
                let flag = Name::RefineFlag.of(&info.name);
                self.line(indent, format!("var {flag} = false;"));
                args.push(format!("&{flag}"));
            }
            Name::Eval
        };
        let value = |d: &EffectId| format!("{prefix}{}", self.effect_name(*d));
        match self.dependency_parts(e) {
            None => args.extend(self.deps_params(e).iter().map(value)),
            Some(parts) => args.extend(parts.iter().enumerate().map(|(k, part)| {
                let values: Vec<String> = part.iter().map(value).collect();
                format!("{}({})", Name::Args.within(k, &info.name), values.join(", "))
            })),
        }
        self.line(
            indent,
            format!("{declare}{prefix}{} = {}({});", self.effect_name(e), function.of(&info.name), args.join(", ")),
        );
    }

    // ---- Refine flags ----------------------------------------------------------------

    /// Declares the refine flag words `mrsl_flags<w>`, all clear.
    pub(super) fn declare_flag_words(&mut self, words: u32) {
        for w in 0..words {
            self.line(1, format!("var {} = 0u;", Name::FlagWord.of(w)));
        }
    }

    /// Sets effect `e`'s refine flag (if it has one) where it refined or refinement is forced.
    pub(super) fn set_refine_flag(&mut self, e: EffectId, indent: usize) {
        if let Some(k) = self.i.interface.refine_bit[e.index()] {
            let (word, mask) = bit(k);
            let name = &self.checked().effects[e.index()].name;
            let (flag, word) = (Name::RefineFlag.of(name), Name::FlagWord.of(word));
            self.line(indent, format!("if ({flag} || {FORCE}) {{ {word} |= {mask}u; }}"));
        }
    }
}

/// The `refine;` statements in `s`, at any depth.
fn refine_statements(s: &Stmt, out: &mut HashSet<NodeId>) {
    match &s.kind {
        StmtKind::Refine => {
            out.insert(s.id);
        }
        StmtKind::If { then, otherwise, .. } => {
            refine_statements(then, out);
            if let Some(o) = otherwise {
                refine_statements(o, out);
            }
        }
        StmtKind::For { body, .. } => refine_statements(body, out),
        StmtKind::Block(b) => b.stmts.iter().for_each(|sub| refine_statements(sub, out)),
        _ => {}
    }
}

/// Calls `f` on the top-level expressions of `s` and its sub-statements, like
/// `visit_stmt_exprs`, except inside the statements in `skipped`.
fn visit_kept_exprs<'a>(s: &'a Stmt, skipped: &HashSet<NodeId>, f: &mut dyn FnMut(&'a Expr)) {
    if skipped.contains(&s.id) {
        return;
    }
    match &s.kind {
        StmtKind::If { cond, then, otherwise } => {
            f(cond);
            visit_kept_exprs(then, skipped, f);
            if let Some(o) = otherwise {
                visit_kept_exprs(o, skipped, f);
            }
        }
        StmtKind::For { init, cond, step, body } => {
            // A kept loop's header is kept whole.
            for header in [init, step].into_iter().flatten() {
                visit_stmt_exprs(header, f);
            }
            if let Some(c) = cond {
                f(c);
            }
            visit_kept_exprs(body, skipped, f);
        }
        StmtKind::Block(b) => b.stmts.iter().for_each(|s| visit_kept_exprs(s, skipped, f)),
        _ => visit_stmt_exprs(s, f),
    }
}

/// The WGSL of a field of Bevy's deferred G-buffer texel `g` (a `vec4<u32>`),
/// as Bevy 0.19's `pbr_input_from_deferred_gbuffer` decodes it.
fn bevy_field(field: BevyField) -> String {
    let normal = "vec2<f32>(f32(g.w & 0xfffu), f32((g.w >> 12u) & 0xfffu)) / 4095.0 * 2.0 - 1.0";
    match field {
        BevyField::BaseColor => "pow(unpack4x8unorm(g.x).rgb, vec3<f32>(2.2))".into(),
        BevyField::PerceptualRoughness => "unpack4x8unorm(g.x).a".into(),
        BevyField::Emissive => format!("{RGB9E5}(g.y)"),
        BevyField::Reflectance => "unpack4x8unorm(g.z).x".into(),
        BevyField::Metallic => "unpack4x8unorm(g.z).y".into(),
        BevyField::Occlusion => "unpack4x8unorm(g.z).z".into(),
        BevyField::Normal => format!("{OCTAHEDRAL}({normal})"),
        BevyField::Flags => "(g.w >> 24u) & 0xffu".into(),
    }
}

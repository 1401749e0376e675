//! Warnings about what a derivative computes, which no type error shows:
//!
//! - W0004: a coarse effect whose *value* scales with the sample spacing. A
//!   derivative is taken across the spacing (2 or 4 pixels at coarse rate, 1
//!   in the reference and wherever a pixel refines), so a value built on one
//!   changes with the mode: an AO term built on `fwidth(normal)` comes out
//!   about 4 times too dark at coarse 4x4. The check is a dimension analysis
//!   in powers of the spacing: a derivative adds one, `*` adds, `/`
//!   subtracts, `sqrt` halves, `normalize` and `sign` give zero; a value of
//!   power zero does not change with the rate (a normal rebuilt by
//!   `normalize(cross(ddx(p), ddy(p)))`, a curvature `dot(ddx(n), ddx(p)) /
//!   dot(ddx(p), ddx(p))`), and a derivative that only decides refinement is
//!   not part of the value.
//! - W0005: a derivative of a value that is the same at every pixel (made of
//!   uniforms, constants and literals only): it is zero everywhere.

use crate::builtins::Builtin;
use crate::check::{Callee, Checked, LocalId, Symbol};
use crate::deriv::DerivInfo;
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::{AssignOp, BinaryOp, EffectBody, Expr, ExprKind, Item, NodeId, Rate, Stmt, StmtKind};
use crate::syntax::visit_expr;
use std::collections::{HashMap, HashSet};

/// W0004 and W0005 for the program's derivative sites.
pub fn warnings(checked: &Checked, deriv: &DerivInfo) -> Vec<Diagnostic> {
    let mut out = vec![];
    let zeros: Vec<_> =
        deriv.sites.iter().filter(|s| s.builtin != Builtin::Sample && invariant(checked, s.operand)).collect();
    for site in &zeros {
        out.push(
            Diagnostic::warning(
                "W0005",
                format!("`{}` of a value that is the same at every pixel", site.builtin.name()),
            )
            .with_label(Label::primary(site.operand.span, "made of uniforms, constants and literals only"))
            .with_note(
                "help: this derivative is zero everywhere: differentiate a value that varies across the \
                     screen (an input or an effect), or drop it",
            ),
        );
    }
    for (k, effect) in checked.effects.iter().enumerate() {
        let calls: Vec<_> = deriv
            .sites
            .iter()
            .filter(|s| s.effect.index() == k && s.builtin != Builtin::Sample && !s.decides_only)
            .filter(|s| !zeros.iter().any(|z| z.node == s.node))
            .collect();
        let zero: HashSet<NodeId> = zeros.iter().map(|z| z.node).collect();
        if effect.rate != Rate::Coarse || calls.is_empty() || !scales_with_spacing(checked, effect, &zero) {
            continue;
        }
        let mut d =
            Diagnostic::warning("W0004", format!("the value of coarse effect `{}` changes with the rate", effect.name))
                .with_label(Label::primary(
                    calls[0].call,
                    "taken across the sample spacing: 2 or 4 pixels at coarse rate, 1 in the reference",
                ));
        for site in &calls[1..] {
            d = d.with_label(Label::secondary(site.call, "and this one"));
        }
        out.push(d.with_note(
            "help: decide refinement with a derivative instead (`if (fwidth(x) > t) refine;`), divide by a \
             derivative of the same spacing (`dot(ddx(n), ddx(p)) / dot(ddx(p), ddx(p))`, a curvature) or \
             normalize, or compute the term in a fine effect, per pixel",
        ));
    }
    out
}

/// Whether `operand` reads only uniforms, constants and literals (calls of
/// builtins and functions, which read no inputs or effects, included).
fn invariant(checked: &Checked, operand: &Expr) -> bool {
    let mut varies = false;
    visit_expr(operand, &mut |e| {
        if let ExprKind::Name(_) = e.kind {
            varies |= !matches!(checked.symbols.get(&e.id), Some(Symbol::Uniform(_) | Symbol::Const(_)));
        }
    });
    !varies
}

/// A value's power of the sample spacing, in halves (`sqrt` of a squared
/// length is a length).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Power {
    /// A literal or a zero-initialised local: takes the power of what it meets.
    Free,
    Halves(i32),
    /// Two different powers meet (`1.0 + fwidth(x)`), or a function of a
    /// value that is not dimensionless (`saturate(fwidth(x))`).
    Mixed,
}

impl Power {
    const ZERO: Power = Power::Halves(0);

    fn unify(self, other: Power) -> Power {
        match (self, other) {
            (Power::Free, p) | (p, Power::Free) => p,
            (Power::Halves(a), Power::Halves(b)) if a == b => self,
            _ => Power::Mixed,
        }
    }
    fn times(self, other: Power, sign: i32) -> Power {
        match (self, other) {
            (Power::Mixed, _) | (_, Power::Mixed) => Power::Mixed,
            (Power::Halves(a), Power::Halves(b)) => Power::Halves(a + sign * b),
            (Power::Halves(a), Power::Free) => Power::Halves(a),
            (Power::Free, Power::Halves(b)) => Power::Halves(sign * b),
            (Power::Free, Power::Free) => Power::Free,
        }
    }
    /// The power of a function that needs a dimensionless argument.
    fn dimensionless(self) -> Power {
        if matches!(self, Power::Free | Power::ZERO) { self } else { Power::Mixed }
    }
    /// The power of a function of a value that drops its scale: a direction
    /// (`normalize`), a sign, a comparison of like quantities.
    fn scale_free(self) -> Power {
        if self == Power::Mixed { Power::Mixed } else { Power::ZERO }
    }
}

/// Whether a coarse effect's value has a power of the spacing other than 0.
/// `zero` holds the derivatives of invariant values (W0005), which are zero
/// and take the power of what they meet.
fn scales_with_spacing(checked: &Checked, effect: &crate::check::EffectInfo, zero: &HashSet<NodeId>) -> bool {
    let Item::Effect(decl) = &checked.program.items[effect.item] else { unreachable!("effect ids index effect items") };
    let power = match &decl.body {
        EffectBody::Expr(e) => Powers { locals: HashMap::new(), zero }.of(checked, e),
        EffectBody::Block(b) => {
            let mut powers = Powers { locals: HashMap::new(), zero };
            // Loops carry powers from one iteration to the next: run the body
            // until nothing changes (each local's power only moves towards
            // `Mixed`, so a few rounds settle).
            for _ in 0..4 {
                let before = powers.locals.clone();
                b.stmts.iter().for_each(|s| powers.statement(checked, s));
                if powers.locals == before {
                    break;
                }
            }
            effect.result.and_then(|r| powers.locals.get(&r).copied()).unwrap_or(Power::Free)
        }
    };
    !matches!(power, Power::Free | Power::ZERO)
}

/// The power of each local of an effect body, as its statements assign them.
struct Powers<'z> {
    locals: HashMap<LocalId, Power>,
    zero: &'z HashSet<NodeId>,
}

impl Powers<'_> {
    fn statement(&mut self, checked: &Checked, s: &Stmt) {
        match &s.kind {
            StmtKind::Local { init, .. } => {
                if let Some(&local) = checked.local_decls.get(&s.id) {
                    let power = init.as_ref().map_or(Power::Free, |e| self.of(checked, e));
                    let old = self.locals.get(&local).copied().unwrap_or(Power::Free);
                    self.locals.insert(local, old.unify(power));
                }
            }
            StmtKind::Assign { target, op, value } => {
                let Some(local) = crate::deriv::root_local(target, checked) else { return };
                let value = self.of(checked, value);
                let old = self.locals.get(&local).copied().unwrap_or(Power::Free);
                let new = match op {
                    AssignOp::Mul => old.times(value, 1),
                    AssignOp::Div => old.times(value, -1),
                    // A later assignment may sit in a branch: keep what the local held too.
                    AssignOp::Set | AssignOp::Add | AssignOp::Sub => old.unify(value),
                };
                self.locals.insert(local, new);
            }
            StmtKind::If { then, otherwise, .. } => {
                self.statement(checked, then);
                if let Some(o) = otherwise {
                    self.statement(checked, o);
                }
            }
            StmtKind::For { init, step, body, .. } => {
                for sub in [init.as_deref(), Some(body.as_ref()), step.as_deref()].into_iter().flatten() {
                    self.statement(checked, sub);
                }
            }
            StmtKind::Block(b) => b.stmts.iter().for_each(|sub| self.statement(checked, sub)),
            StmtKind::Step { .. } | StmtKind::Refine | StmtKind::Return(_) | StmtKind::Break | StmtKind::Continue => {}
        }
    }

    fn of(&self, checked: &Checked, e: &Expr) -> Power {
        match &e.kind {
            ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) => Power::Free,
            ExprKind::Name(_) => match checked.symbols.get(&e.id) {
                Some(Symbol::Local(local)) => self.locals.get(local).copied().unwrap_or(Power::Free),
                _ => Power::ZERO,
            },
            ExprKind::Unary(_, a) | ExprKind::Field { base: a, .. } | ExprKind::Index { base: a, .. } => {
                self.of(checked, a)
            }
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (self.of(checked, a), self.of(checked, b));
                match op {
                    BinaryOp::Mul => a.times(b, 1),
                    BinaryOp::Div => a.times(b, -1),
                    BinaryOp::Add | BinaryOp::Sub | BinaryOp::Rem => a.unify(b),
                    // A comparison of like quantities, and logic on its results.
                    _ => a.unify(b).scale_free(),
                }
            }
            ExprKind::Ternary(c, a, b) => {
                let choice = self.of(checked, c);
                self.of(checked, a).unify(self.of(checked, b)).times(choice.dimensionless(), 1)
            }
            ExprKind::Call { .. } if self.zero.contains(&e.id) => Power::Free,
            ExprKind::Call { args, .. } => {
                let args: Vec<Power> = args.iter().map(|a| self.of(checked, a)).collect();
                call_power(checked.callees.get(&e.id), &args)
            }
        }
    }
}

/// A call's power from its arguments'.
fn call_power(callee: Option<&Callee>, args: &[Power]) -> Power {
    let all = |f: fn(Power, Power) -> Power| args.iter().copied().reduce(f).unwrap_or(Power::Free);
    let Some(Callee::Builtin(builtin)) = callee else {
        // A constructor keeps its components' power; a function of the
        // program needs dimensionless arguments.
        return match callee {
            Some(Callee::Construct(_)) => all(Power::unify),
            _ => all(Power::unify).dimensionless(),
        };
    };
    use Builtin as B;
    match builtin {
        B::Ddx | B::Ddy | B::Fwidth | B::DdxSurface | B::DdySurface | B::FwidthSurface => {
            args[0].times(Power::Halves(2), 1)
        }
        B::Abs | B::Min | B::Max | B::Clamp | B::Length | B::Distance | B::Round | B::Trunc | B::Transpose => {
            all(Power::unify)
        }
        B::Mix | B::Lerp => args[0].unify(args[1]).times(args[2].dimensionless(), 1),
        // `faceforward(n, i, nref)` is `n` or `-n`, as the sign of a dot product decides.
        B::FaceForward => args[0].times(args[1].times(args[2], 1).scale_free(), 1),
        // `reflect(i, n)` with a unit `n`.
        B::Reflect => args[0].times(args[1].dimensionless(), 1),
        B::Dot | B::Cross => args[0].times(args[1], 1),
        B::Normalize | B::Sign => args[0].scale_free(),
        B::Sqrt => half(args[0], 1),
        B::InverseSqrt => half(args[0], -1),
        B::Atan2 | B::Step | B::Smoothstep => all(Power::unify).scale_free(),
        _ => all(Power::unify).dimensionless(),
    }
}

/// `sqrt` (`sign` 1) or `inversesqrt` (-1) of a value of `power`.
fn half(power: Power, sign: i32) -> Power {
    match power {
        Power::Halves(h) if h % 2 == 0 => Power::Halves(sign * h / 2),
        Power::Halves(_) | Power::Mixed => Power::Mixed,
        Power::Free => Power::Free,
    }
}

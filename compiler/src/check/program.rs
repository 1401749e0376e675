//! Whole-program checks, run once every body is checked: recursion, which
//! WGSL forbids, the presence of an output, and effects no output needs.

use super::{Checker, FunctionId, err};
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;

impl Checker<'_> {
    pub(super) fn check_function_recursion(&mut self) {
        // WGSL forbids recursion; report each function that can reach itself.
        let n = self.out.functions.len();
        for start in 0..n {
            let mut stack = vec![start];
            let mut seen = vec![false; n];
            while let Some(f) = stack.pop() {
                for callee in &self.out.functions[f].calls {
                    if callee.index() == start {
                        let decl = self.out.function_decl(FunctionId(start as u32));
                        let d = err(
                            "E0307",
                            format!("function `{}` is recursive", decl.name.name),
                            decl.name.span,
                            "calls itself, directly or indirectly",
                        )
                        .with_note("recursion is not available on GPUs (WGSL forbids it)");
                        self.diagnostics.push(d);
                        stack.clear();
                        break;
                    }
                    if !seen[callee.index()] {
                        seen[callee.index()] = true;
                        stack.push(callee.index());
                    }
                }
            }
        }
    }

    pub(super) fn check_outputs_and_usage(&mut self) {
        let effects = &self.out.effects;
        if !effects.iter().any(|e| e.rate == Rate::Out) {
            let span = self.out.program.items.last().map(|i| i.name().span).unwrap_or_default();
            self.diagnostics.push(
                err("E0601", "the program has no output", span, "no `fine out` declared")
                    .with_note("declare at least one target, e.g. `fine out float4 color = ...;`"),
            );
        }
        // Unused-effect warnings only on programs without errors: after an
        // error (a duplicate, a bad name) they are mostly noise.
        if self.diagnostics.iter().any(|d| d.is_error()) {
            return;
        }
        // An effect is used when an output needs it, directly or through other effects.
        let mut live = vec![false; effects.len()];
        let mut stack: Vec<usize> = (0..effects.len()).filter(|&i| effects[i].rate == Rate::Out).collect();
        while let Some(i) = stack.pop() {
            if !std::mem::replace(&mut live[i], true) {
                stack.extend(effects[i].deps.iter().map(|(d, _)| d.index()));
            }
        }
        for (i, e) in effects.iter().enumerate() {
            if !live[i] {
                let read = effects.iter().any(|u| u.deps.iter().any(|(d, _)| d.index() == i));
                self.diagnostics.push(
                    Diagnostic::warning("W0001", format!("effect `{}` is never used", e.name))
                        .with_label(Label::primary(
                            e.name_span,
                            if read {
                                "read only by effects that no output needs"
                            } else {
                                "not read by any effect or output"
                            },
                        ))
                        .with_note("it will not be computed"),
                );
            }
        }
    }
}

//! `mrsl::analyze`, the editors' view of a program: declarations and the
//! references to them, each effect's facts (the same as the compiled
//! layout's), the quick fixes diagnostics name, and no panic on programs
//! cut anywhere.

use mrsl::{DeclarationKind as Kind, analyze};

const PROGRAM: &str = "\
@key(0.4) in float3 normal;
uniform float3 light = float3(0.0, 1.0, 0.0);
const float K = 0.5;
float shade(float x) { return x * K; }
coarse effect float diffuse {
    float d = saturate(dot(normal, light));
    if (fwidth(d) > 0.05) {
        refine;
    } else if (d < 0.0) refine;
    diffuse = shade(d);
}
coarse effect float rim = 1.0 - diffuse;
fine out float4 color = float4(float3(diffuse + rim), 1.0);
";

/// The text at a span of `PROGRAM`.
fn at(span: mrsl::Span) -> &'static str {
    &PROGRAM[span.range()]
}

#[test]
fn declarations_references_and_effect_facts() {
    let analysis = analyze(PROGRAM);
    assert!(analysis.diagnostics.is_empty(), "{:?}", analysis.diagnostics);
    let decl = |name: &str| analysis.declarations.iter().position(|d| d.name == name).unwrap();
    let kinds: Vec<(&str, Kind, &str)> =
        analysis.declarations.iter().map(|d| (d.name.as_str(), d.kind, d.ty.as_str())).collect();
    assert_eq!(
        kinds,
        [
            ("normal", Kind::Input, "float3"),
            ("light", Kind::Uniform, "float3"),
            ("K", Kind::Const, "float"),
            ("shade", Kind::Function, "float"),
            ("diffuse", Kind::Effect, "float"),
            ("rim", Kind::Effect, "float"),
            ("color", Kind::Output, "float4"),
            ("x", Kind::Parameter, "float"),
            ("d", Kind::Local, "float"),
        ]
    );
    let shade = &analysis.declarations[decl("shade")];
    assert_eq!((shade.signature.as_str(), at(shade.name_span)), ("float shade(float x)", "shade"));
    let d = &analysis.declarations[decl("d")];
    assert_eq!(at(d.span), "float d = saturate(dot(normal, light))");
    assert!(
        at(d.visible.unwrap()).trim_start_matches(";").trim_start().starts_with("if (fwidth(d)"),
        "visible after its declaration"
    );
    // Every reference covers its name, and they are where the names are read.
    let refs = |name: &str| -> Vec<&str> {
        let index = decl(name);
        analysis.references.iter().filter(|r| r.declaration == index).map(|r| at(r.span)).collect()
    };
    assert_eq!(refs("normal"), ["normal"]);
    assert_eq!(refs("K"), ["K"]);
    assert_eq!(refs("shade"), ["shade"], "a call refers to its function");
    assert_eq!(refs("d"), ["d", "d", "d"]);
    // `diffuse = ...` in its own body assigns the effect; `rim` and `color` read it.
    assert_eq!(refs("diffuse").len(), 3);

    let diffuse = &analysis.effects[analysis.declarations[decl("diffuse")].effect.unwrap()];
    assert_eq!(diffuse.rate, "coarse");
    assert_eq!(diffuse.predicates, ["fwidth(d) > 0.05", "!(fwidth(d) > 0.05) && d < 0.0"]);
    let facts = diffuse.layout.as_ref().expect("no errors: the layout's facts");
    assert_eq!(facts.keys, ["normal"]);
    assert!(facts.live && facts.operations.unwrap() > 5 && facts.inlined_operations.unwrap() > 5);
    assert_eq!(facts.sample_evaluations, Some(1));
    assert!(facts.slot.is_some());
    assert_eq!(analysis.effects[analysis.declarations[decl("color")].effect.unwrap()].rate, "out");
}

#[test]
fn a_program_with_errors_keeps_its_declarations_but_not_its_layout() {
    let source = PROGRAM.replace("shade(d)", "shade(d) + missing");
    let analysis = analyze(&source);
    assert_eq!(analysis.diagnostics.iter().map(|d| d.code).collect::<Vec<_>>(), ["E0100"]);
    assert!(analysis.declarations.iter().any(|d| d.name == "diffuse"));
    assert!(!analysis.references.is_empty());
    assert!(analysis.effects.iter().all(|e| e.layout.is_none()));
    let unparsed = analyze("in float3 normal\n");
    assert_eq!(unparsed.diagnostics.len(), 1);
    assert!(unparsed.declarations.is_empty());
}

/// The facts are the compiled layout's, on every example.
#[test]
fn effect_facts_are_the_layouts() {
    for (name, source) in crate::examples() {
        let analysis = analyze(&source);
        let program = mrsl::compile(&source, &mrsl::Options::for_modes(&[mrsl::Mode::Coarse4x4])).unwrap();
        assert_eq!(analysis.effects.len(), program.layout.effects.len(), "{name}");
        for (facts, effect) in analysis.effects.iter().zip(&program.layout.effects) {
            let layout = facts.layout.as_ref().unwrap();
            assert_eq!(facts.name, effect.name, "{name}");
            assert_eq!(
                (layout.operations, layout.slot.as_ref().map(|s| s.index), &layout.keys, layout.sample_evaluations),
                (effect.operations, effect.slot, &effect.keys, effect.sample_evaluations),
                "{name}: {}",
                effect.name
            );
            if let Some(slot) = &layout.slot {
                let mut sharing = slot.shared_with.clone();
                sharing.push(effect.name.clone());
                sharing.sort();
                let mut expected = program.layout.interface.slots[slot.index].effects.clone();
                expected.sort();
                assert_eq!(sharing, expected, "{name}: {}", effect.name);
            }
        }
    }
}

#[test]
fn quick_fixes_replace_the_primary_span_with_the_named_word() {
    let fix = |source: &str| {
        let d = mrsl::check(source).into_iter().find(|d| d.is_error()).unwrap();
        mrsl::quick_fix(&d).map(|f| (source[f.span.range()].to_string(), f.replacement))
    };
    let header = "in float3 normal;\n";
    let foreign = format!("{header}fine out float4 color = float4(vec3(normal), 1.0);\n");
    assert_eq!(fix(&foreign), Some(("vec3".into(), "float3".into())));
    let typo = format!("{header}fine out float4 color = float4(normall, 1.0);\n");
    assert_eq!(fix(&typo), Some(("normall".into(), "normal".into())));
    let prose =
        format!("{header}fn f(n: float3) -> float3 {{ return n; }}\nfine out float4 color = float4(normal, 1.0);\n");
    assert_eq!(fix(&prose), None, "a rewrite described in prose is no mechanical fix");
}

/// An editor analyses every state of a program as it is typed.
#[test]
fn analyze_never_panics_on_a_program_cut_anywhere() {
    for (_, source) in crate::examples() {
        let cuts = (0..source.len()).step_by(53).filter(|&i| source.is_char_boundary(i));
        for cut in cuts {
            let analysis = analyze(&source[..cut]);
            for r in &analysis.references {
                assert!(r.declaration < analysis.declarations.len());
            }
        }
    }
}

//! Words of GLSL, HLSL and WGSL: every row of the compiler's table, written
//! where a newcomer writes it, gets one diagnostic whose help names what mrsl
//! writes instead (never a list of expected tokens), and docs/language.md's
//! "Coming from GLSL, HLSL or WGSL" table is the table's own rendering.

use mrsl::internals::{FOREIGN_WORDS, ForeignKind, foreign_rows};
use std::path::Path;

/// Words whose example line is a top-level declaration, not a statement.
const DECLARING: &[&str] =
    &["#", "struct", "cbuffer", "layout", "fn", "static", "void", "typedef", "precision", "override", "float3 f("];

/// `example` with `word` in place of the row's word it shows, in a program
/// where `n` is a `float3` local and `uv` a `float2` channel.
fn program(example: &str, shown: &str, word: &str) -> String {
    let top = DECLARING.iter().any(|d| example.starts_with(d));
    placed(&example.replacen(shown, word, 1), top)
}

/// `line` as a top-level declaration or as a statement of an effect body.
fn placed(line: &str, top: bool) -> String {
    let (declaration, statement) = if top { (line, "") } else { ("", line) };
    format!(
        "in float3 normal;\nin float2 uv;\n{declaration}\ncoarse effect float3 e {{\n    float3 n = normal;\n    \
         {statement}\n    e = n;\n}}\nfine out float4 color = float4(e, 1.0);\n"
    )
}

/// The first error of `source`, with the text its primary label covers.
fn first_error(source: &str) -> (mrsl::Diagnostic, String) {
    let diagnostics = mrsl::check(source);
    let d = diagnostics.into_iter().find(|d| d.is_error()).unwrap_or_else(|| panic!("no error for:\n{source}"));
    let span = d.span().unwrap_or_else(|| panic!("no span on {}:\n{source}", d.code));
    let text = source[span.start as usize..span.end as usize].to_string();
    (d, text)
}

#[track_caller]
fn assert_named_fix(source: &str, word: &str, code: &str, instead: &str) {
    let (d, text) = first_error(source);
    let rendered = mrsl::render_all(std::slice::from_ref(&d), "t.mrsl", source);
    assert_eq!((d.code, text.as_str()), (code, word), "{rendered}");
    assert!(d.notes.iter().any(|n| n.starts_with("help: mrsl writes") && n.contains(instead)), "{rendered}");
    assert!(!d.notes.iter().any(|n| n.starts_with("expected")), "a list of expected tokens:\n{rendered}");
    // Where the help names one word for a type or function, an editor's
    // quick fix puts it in the word's place; syntax errors get none.
    // (`float` (mrsl's floats are 32-bit)` names `float`; a sentence or a
    // call, whose arguments may differ (`sample(t, s, uv)`), names nothing.)
    let one_word = instead
        .strip_prefix('`')
        .and_then(|s| s.split_once('`'))
        .filter(|(w, rest)| {
            w.chars().all(|c| c.is_alphanumeric() || c == '_') && (rest.is_empty() || rest.starts_with(" ("))
        })
        .map(|(w, _)| w);
    let expected = one_word.filter(|_| code != "E0003").map(|w| (d.span().unwrap(), w.to_string()));
    assert_eq!(mrsl::quick_fix(&d).map(|f| (f.span, f.replacement)), expected, "{rendered}");
}

#[test]
fn every_foreign_word_gets_its_fix() {
    for row in FOREIGN_WORDS {
        let shown = row.words.iter().find(|w| row.example.contains(**w)).expect("the example shows a word of its row");
        let code = match row.kind {
            // WGSL's generic types stop the parser at their `<`.
            ForeignKind::Type if row.example.contains('<') => "E0003",
            ForeignKind::Type => "E0102",
            ForeignKind::Function => "E0100",
            ForeignKind::Keyword => "E0003",
        };
        for word in row.words {
            assert_named_fix(&program(row.example, shown, word), word, code, row.instead);
        }
    }
}

#[test]
fn vector_and_matrix_families_name_the_mrsl_type() {
    let cases = [
        ("vec3", "`float3`"),
        ("vec4f", "`float4`"),
        ("vec2i", "`int2`"),
        ("uvec3", "`uint3`"),
        ("bvec2", "`bool2`"),
        ("half3", "`float3`"),
        ("min16float4", "`float4`"),
        ("mat3", "`float3x3`"),
        ("mat4x4f", "`float4x4`"),
        ("mat3x2", "a square matrix"),
        ("float4x3", "a square matrix"),
        ("half2x2", "`float2x2`"),
    ];
    for (word, instead) in cases {
        assert_named_fix(&program("vec3 k;", "vec3", word), word, "E0102", instead);
    }
    // WGSL's generic spelling stops the parser at `<`: E0003 on the type's word.
    assert_named_fix(&program("vec3<f32> k = n;", "vec3", "vec3"), "vec3", "E0003", "`float3`");
    assert_named_fix(&program("texture_2d<f32> t;", "texture_2d", "texture_2d"), "texture_2d", "E0003", "texture2d");
}

#[test]
fn arrays_and_names_that_are_foreign_words() {
    // A local or constant array: E0003 at its `[`.
    for (example, top) in [("float3 dirs[2];", false), ("const float W[3] = 1.0;", true)] {
        let source = placed(example, top);
        let (d, text) = first_error(&source);
        assert_eq!((d.code, text.as_str()), ("E0003", "["), "{source}");
        assert!(d.notes.iter().any(|n| n.contains("one local per element")));
    }
    // A foreign word used as a name is a name: a missing `;` after it stays
    // the parser's "expected `;`".
    let source = placed("float loop = 1.0;\n    loop = 2.0\n    n.x = loop;", false);
    let (d, _) = first_error(&source);
    assert!(d.code == "E0002" && d.message.starts_with("expected `;`"), "{}", d.message);
    // A directive nobody lists is still E0003, with its own word.
    let (d, text) = first_error(&placed("#warning 1", true));
    assert_eq!((d.code, text.as_str()), ("E0003", "#warning"));
}

/// Sourcegen: the docs' table is regenerated between its markers; a stale
/// table is rewritten (commit the file) and the test fails.
#[test]
fn docs_table_is_the_compilers() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/language.md");
    let docs = std::fs::read_to_string(&path).expect("docs/language.md is readable");
    let (start, end) =
        ("<!-- foreign words: generated by compiler/tests/it/foreign.rs -->", "<!-- end of foreign words -->");
    let (Some(open), Some(close)) = (docs.find(start), docs.find(end)) else {
        panic!("docs/language.md lacks the markers {start} ... {end}");
    };
    let table = format!("{start}\n{}\n", foreign_rows().join("\n"));
    let fresh = format!("{}{table}{}", &docs[..open], &docs[close..]);
    if fresh != docs {
        std::fs::write(&path, fresh).expect("docs/language.md is writable");
        panic!("docs/language.md's table of foreign words was stale: rewritten, commit it");
    }
}

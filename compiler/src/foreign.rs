//! Words of other shading languages (GLSL, HLSL, WGSL) that a shader
//! programmer writes out of habit, each with what mrsl writes instead.
//!
//! One table serves the parser's diagnostics (a `while`, `discard`, `struct`
//! or `#include` is E0003 with the fix, not a list of expected tokens), the
//! checker's (an unknown type `vec3` or function `mul` gets the mrsl
//! spelling as its help) and the "Coming from GLSL, HLSL or WGSL" table of
//! docs/language.md, which a test regenerates from [`rows`].

use crate::diagnostic::{Diagnostic, Label};
use crate::span::Span;

/// What a foreign word is, which decides the diagnostic it gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A type name: E0102 (unknown type) with the mrsl type as its help.
    Type,
    /// A function: E0100 (unknown function) with the mrsl form as its help.
    Function,
    /// A statement or declaration keyword, or a preprocessor directive:
    /// E0003, wherever the parser or the checker meets it.
    Keyword,
}

/// One row of the table: words that share a fix.
pub struct Foreign {
    /// The words as written, e.g. `["dFdx", "ddx_fine", "dpdxFine"]`.
    pub words: &'static [&'static str],
    /// The languages that write them.
    pub from: &'static str,
    pub kind: Kind,
    /// What mrsl writes instead (Markdown with code in backticks).
    pub instead: &'static str,
    /// A line a newcomer writes, for the test that every row is diagnosed
    /// (compiler/tests/it/foreign.rs): a top-level declaration when it starts
    /// with `#` or a keyword that declares (`struct`, `fn`, `void`, ...), else
    /// a statement of an effect body where `n` is a `float3` and `uv` a `float2`.
    pub example: &'static str,
}

/// Vector and matrix families of other languages: `STEM` + size + `SUFFIX`.
struct Family {
    stem: &'static str,
    suffix: &'static str,
    from: &'static str,
    /// The mrsl element type: `float`, `int`, `uint` or `bool`.
    element: &'static str,
    matrix: bool,
}

const FAMILIES: &[Family] = &[
    Family { stem: "vec", suffix: "", from: "GLSL, WGSL", element: "float", matrix: false },
    Family { stem: "vec", suffix: "f", from: "WGSL", element: "float", matrix: false },
    Family { stem: "vec", suffix: "h", from: "WGSL", element: "float", matrix: false },
    Family { stem: "vec", suffix: "i", from: "WGSL", element: "int", matrix: false },
    Family { stem: "vec", suffix: "u", from: "WGSL", element: "uint", matrix: false },
    Family { stem: "ivec", suffix: "", from: "GLSL", element: "int", matrix: false },
    Family { stem: "uvec", suffix: "", from: "GLSL", element: "uint", matrix: false },
    Family { stem: "bvec", suffix: "", from: "GLSL", element: "bool", matrix: false },
    Family { stem: "dvec", suffix: "", from: "GLSL", element: "float", matrix: false },
    Family { stem: "half", suffix: "", from: "HLSL", element: "float", matrix: false },
    Family { stem: "double", suffix: "", from: "HLSL", element: "float", matrix: false },
    Family { stem: "min16float", suffix: "", from: "HLSL", element: "float", matrix: false },
    Family { stem: "mat", suffix: "", from: "GLSL, WGSL", element: "float", matrix: true },
    Family { stem: "mat", suffix: "f", from: "WGSL", element: "float", matrix: true },
    Family { stem: "half", suffix: "", from: "HLSL", element: "float", matrix: true },
    Family { stem: "float", suffix: "", from: "HLSL", element: "float", matrix: true },
];

/// The words that are not families, in the order of the docs' table.
pub const TABLE: &[Foreign] = &[
    Foreign {
        words: &["f32", "f16", "half", "double", "min16float"],
        from: "WGSL, HLSL",
        kind: Kind::Type,
        instead: "`float` (mrsl's floats are 32-bit)",
        example: "half k = 0.5;",
    },
    Foreign { words: &["i32"], from: "WGSL", kind: Kind::Type, instead: "`int`", example: "i32 k = 1;" },
    Foreign {
        words: &["u32", "unsigned", "dword"],
        from: "WGSL, GLSL, HLSL",
        kind: Kind::Type,
        instead: "`uint`",
        example: "u32 k = 1u;",
    },
    Foreign {
        words: &["void"],
        from: "GLSL, HLSL",
        kind: Kind::Type,
        instead: "a return type: every function returns a value (`float3 f(float3 n) { return n; }`); an effect \
                  assigns its own name instead",
        example: "void f() { }",
    },
    Foreign {
        words: &["sampler2D", "texture_2d", "Texture2D"],
        from: "GLSL, WGSL, HLSL",
        kind: Kind::Type,
        instead: "`uniform texture2d t;` and `uniform sampler s;`, read with `sample(t, s, uv)`",
        example: "sampler2D t;",
    },
    Foreign { words: &["array"], from: "WGSL", kind: Kind::Type, instead: LOCAL_ARRAY, example: "array<f32, 4> a;" },
    Foreign {
        words: &["SamplerState", "sampler_comparison"],
        from: "HLSL, WGSL",
        kind: Kind::Type,
        instead: "`sampler`",
        example: "SamplerState s;",
    },
    Foreign {
        words: &["mul"],
        from: "HLSL",
        kind: Kind::Function,
        instead: "`m * v`: `*` on a matrix and a vector multiplies column vectors, as GLSL and WGSL do, so HLSL's \
                  `mul(v, m)` is `transpose(m) * v`",
        example: "n = mul(n, n);",
    },
    Foreign { words: &["frac"], from: "HLSL", kind: Kind::Function, instead: "`fract(x)`", example: "n = frac(n);" },
    Foreign {
        words: &["rsqrt", "inverseSqrt"],
        from: "HLSL, WGSL",
        kind: Kind::Function,
        instead: "`inversesqrt(x)`",
        example: "n = rsqrt(n);",
    },
    Foreign { words: &["rcp"], from: "HLSL", kind: Kind::Function, instead: "`1.0 / x`", example: "n = rcp(n);" },
    Foreign {
        words: &["mad", "fma"],
        from: "HLSL, GLSL, WGSL",
        kind: Kind::Function,
        instead: "`a * b + c`",
        example: "n = mad(n, n, n);",
    },
    Foreign {
        words: &["fmod"],
        from: "HLSL",
        kind: Kind::Function,
        instead: "`x - y * trunc(x / y)` (the remainder with the sign of `x`)",
        example: "n = fmod(n, n);",
    },
    Foreign {
        words: &["mod"],
        from: "GLSL",
        kind: Kind::Function,
        instead: "`x - y * floor(x / y)` (GLSL's `mod`, with the sign of `y`)",
        example: "n = mod(n, n);",
    },
    Foreign {
        words: &["log10"],
        from: "HLSL",
        kind: Kind::Function,
        instead: "`log2(x) * 0.30103` (log10(2))",
        example: "n = log10(n);",
    },
    Foreign {
        words: &["sincos"],
        from: "HLSL",
        kind: Kind::Function,
        instead: "`sin(x)` and `cos(x)`, each assigned to a local",
        example: "float3 s = sincos(n);",
    },
    Foreign {
        words: &["select"],
        from: "WGSL",
        kind: Kind::Function,
        instead: "`c ? t : f` (WGSL's `select(f, t, c)`)",
        example: "n = select(n, n, true);",
    },
    Foreign {
        words: &["inverse"],
        from: "GLSL",
        kind: Kind::Function,
        instead: "an inverse computed by the engine and passed as a `uniform float4x4`, as `@depth` takes it",
        example: "float3x3 m = inverse(m);",
    },
    Foreign {
        words: &["isnan", "isinf"],
        from: "GLSL, HLSL",
        kind: Kind::Function,
        instead: "nothing: WGSL, which mrsl compiles to, has neither, and its compilers may assume no NaN or \
                  infinity",
        example: "bool b = isnan(n.x);",
    },
    Foreign {
        words: &["texture", "texture2D", "tex2D", "textureSample"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Function,
        instead: "`sample(t, s, uv)`, with a `texture2d` and a `sampler` uniform",
        example: "n = texture(n, uv).xyz;",
    },
    Foreign {
        words: &["textureLod", "tex2Dlod", "textureSampleLevel"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Function,
        instead: "`sample_level(t, s, uv, level)`",
        example: "n = textureLod(n, uv, 0.0).xyz;",
    },
    Foreign {
        words: &["textureGrad", "tex2Dgrad", "textureSampleGrad"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Function,
        instead: "`sample_grad(t, s, uv, ddx_uv, ddy_uv)`",
        example: "n = textureGrad(n, uv, uv, uv).xyz;",
    },
    Foreign {
        words: &["texelFetch", "textureLoad"],
        from: "GLSL, WGSL",
        kind: Kind::Function,
        instead: "`load(t, xy, level)`",
        example: "n = texelFetch(n, int2(0), 0).xyz;",
    },
    Foreign {
        words: &["textureSize", "textureDimensions"],
        from: "GLSL, WGSL",
        kind: Kind::Function,
        instead: "`texture_size(t)`",
        example: "int2 size = textureSize(n, 0);",
    },
    Foreign {
        words: &["dFdx", "dFdxFine", "dFdxCoarse", "ddx_fine", "ddx_coarse", "dpdxFine", "dpdxCoarse"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Function,
        instead: "`ddx(v)` (or `dpdx(v)`), one form for every rate ([section 9](#9-derivatives))",
        example: "n = dFdx(n);",
    },
    Foreign {
        words: &["dFdy", "dFdyFine", "dFdyCoarse", "ddy_fine", "ddy_coarse", "dpdyFine", "dpdyCoarse"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Function,
        instead: "`ddy(v)` (or `dpdy(v)`)",
        example: "n = dFdy(n);",
    },
    Foreign {
        words: &["fwidthFine", "fwidthCoarse"],
        from: "GLSL, WGSL",
        kind: Kind::Function,
        instead: "`fwidth(v)`",
        example: "n = fwidthFine(n);",
    },
    Foreign {
        words: &["while", "do"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Keyword,
        instead: "a `for` loop with a bound the compiler can see beside the condition: `for (int i = 0; i < MAX && \
                  cond; i++) { ... }`",
        example: "while (n.x > 0.0) { n.x -= 1.0; }",
    },
    Foreign {
        words: &["loop"],
        from: "WGSL",
        kind: Kind::Keyword,
        instead: "a `for` loop with a bound the compiler can see: `for (int i = 0; i < MAX; i++) { ... }`",
        example: "loop { break; }",
    },
    Foreign {
        words: &["switch", "case", "default"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Keyword,
        instead: "`if (x == 0) { ... } else if (x == 1) { ... } else { ... }`",
        example: "switch (1) { case 0: break; }",
    },
    Foreign {
        words: &["discard"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Keyword,
        instead: "nothing: every pixel's outputs are written; mark pixels where nothing was drawn with \
                  `@background(v)` on a channel, and let the output choose what they show",
        example: "discard;",
    },
    Foreign {
        words: &["struct"],
        from: "GLSL, HLSL, WGSL",
        kind: Kind::Keyword,
        instead: "separate locals, parameters, uniforms or effects, one per field",
        example: "struct Light { float3 dir; };",
    },
    Foreign {
        words: &["cbuffer", "layout"],
        from: "HLSL, GLSL",
        kind: Kind::Keyword,
        instead: "one `uniform` per field (`uniform float3 light_dir;`): the compiler lays out the uniform buffer",
        example: "cbuffer Frame { float3 light_dir; };",
    },
    Foreign {
        words: &["static"],
        from: "HLSL",
        kind: Kind::Keyword,
        instead: "`const` alone: a top-level `const` is already shared by the whole program",
        example: "static const float K = 1.0;",
    },
    Foreign {
        words: &["var", "let"],
        from: "WGSL",
        kind: Kind::Keyword,
        instead: "a local declared with its type: `float3 v = n;`",
        example: "let v = n;",
    },
    Foreign {
        words: &["fn"],
        from: "WGSL",
        kind: Kind::Keyword,
        instead: "a function declared C-style: `float3 f(float3 n, float k) { return n * k; }`",
        example: "fn f(n: vec3f) -> vec3f { return n; }",
    },
    Foreign {
        words: &["override"],
        from: "WGSL",
        kind: Kind::Keyword,
        instead: "a uniform with a default: `uniform float k = 1.0;`",
        example: "override k: f32 = 1.0;",
    },
    Foreign {
        words: &["inout"],
        from: "GLSL, HLSL",
        kind: Kind::Keyword,
        instead: "a parameter passed by value and the new value returned: `float3 f(float3 x) { return x * 2.0; }`",
        example: "float3 f(inout float3 x) { return x; }",
    },
    Foreign {
        words: &["typedef"],
        from: "HLSL",
        kind: Kind::Keyword,
        instead: "the type itself: mrsl has no type aliases",
        example: "typedef float3 color3;",
    },
    Foreign {
        words: &["precision", "highp", "mediump", "lowp"],
        from: "GLSL",
        kind: Kind::Keyword,
        instead: "nothing: floats are 32-bit everywhere",
        example: "precision highp float;",
    },
    Foreign {
        words: &["#include", "#import", "#define_import_path"],
        from: "GLSL, HLSL, WGSL (naga_oil)",
        kind: Kind::Keyword,
        instead: "the functions themselves, copied into the program: mrsl has no preprocessor and no imports yet",
        example: "#include \"brdf.hlsl\"",
    },
    Foreign {
        words: &["#define"],
        from: "GLSL, HLSL",
        kind: Kind::Keyword,
        instead: "`const float PI = 3.14159;` for a value, a function for a macro with parameters",
        example: "#define PI 3.14159",
    },
    Foreign {
        words: &["#version", "#pragma", "#extension", "#if", "#ifdef", "#ifndef", "#else", "#endif", "#undef"],
        from: "GLSL, HLSL",
        kind: Kind::Keyword,
        instead: "nothing: mrsl has no preprocessor, delete the line",
        example: "#version 450",
    },
];

/// What mrsl writes for a local array, which has no word of its own.
pub const LOCAL_ARRAY: &str = "one local per element, or a loop that computes each element where it is used; a \
                               uniform array (`uniform float4 dirs[2] = { ... };`, 16-byte elements) holds \
                               constants, or values the engine sets";

/// The fix for `word`, if it is a foreign word: its kind, languages and help.
pub fn lookup(word: &str) -> Option<(Kind, &'static str, String)> {
    if let Some(row) = TABLE.iter().find(|row| row.words.contains(&word)) {
        return Some((row.kind, row.from, row.instead.to_string()));
    }
    FAMILIES.iter().find_map(|family| family_member(family, word))
}

/// `word` as a member of `family`: `vec3` is `float3`, `mat3x2` has no mrsl
/// type (matrices are square).
fn family_member(family: &Family, word: &str) -> Option<(Kind, &'static str, String)> {
    let size = word.strip_prefix(family.stem)?.strip_suffix(family.suffix)?;
    let digit = |s: &str| s.parse::<u8>().ok().filter(|n| (2..=4).contains(n));
    let instead = if family.matrix {
        let (rows, columns) = match size.split_once('x') {
            Some((r, c)) => (digit(r)?, digit(c)?),
            None if family.stem != "float" && family.stem != "half" => (digit(size)?, digit(size)?),
            None => return None,
        };
        if rows == columns {
            format!("`float{rows}x{rows}`")
        } else {
            "a square matrix: mrsl has `float2x2`, `float3x3` and `float4x4` only".to_string()
        }
    } else {
        format!("`{}{}`", family.element, digit(size)?)
    };
    Some((Kind::Type, family.from, instead))
}

/// The help line for a foreign word: "mrsl writes `float3` (`vec3` is GLSL, WGSL)".
pub fn help(word: &str) -> Option<String> {
    let (_, from, instead) = lookup(word)?;
    Some(format!("help: mrsl writes {instead} (`{word}` is {from})"))
}

/// E0003: `word` at `span` is a keyword or directive of another language.
pub fn keyword_diagnostic(word: &str, span: Span) -> Option<Diagnostic> {
    let (kind, from, instead) = lookup(word)?;
    (kind == Kind::Keyword).then(|| {
        Diagnostic::error("E0003", format!("`{word}` is not mrsl"))
            .with_label(Label::primary(span, format!("from {from}")))
            .with_note(format!("help: mrsl writes {instead}"))
    })
}

/// E0003 for a local or constant array `T name[N]`, at its `[`.
pub fn array_diagnostic(span: Span) -> Diagnostic {
    Diagnostic::error("E0003", "mrsl has no local or constant arrays")
        .with_label(Label::primary(span, "an array declaration"))
        .with_note(format!("help: write {LOCAL_ARRAY}"))
}

/// The docs' "Coming from GLSL, HLSL or WGSL" table, one row per line:
/// `| words | from | mrsl |`, families first.
pub fn rows() -> Vec<String> {
    let mut rows = vec!["| written | in | mrsl writes |".to_string(), "| --- | --- | --- |".to_string()];
    for family in FAMILIES {
        let (word, instead) = match (family.matrix, family.stem) {
            (false, stem) => (format!("`{stem}N{}`", family.suffix), format!("`{}N`", family.element)),
            (true, "float" | "half") => {
                (format!("`{}NxM{}`", family.stem, family.suffix), "`floatNxN` (square only)".to_string())
            }
            (true, stem) => (format!("`{stem}N{0}`, `{stem}NxM{0}`", family.suffix), "`floatNxN` (square only)".into()),
        };
        rows.push(format!("| {word} | {} | {instead} |", family.from));
    }
    for row in TABLE {
        let words: Vec<String> = row.words.iter().map(|w| format!("`{w}`")).collect();
        rows.push(format!("| {} | {} | {} |", words.join(", "), row.from, row.instead));
    }
    rows
}

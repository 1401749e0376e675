//! Unit tests of the formatter: the layout, the comments, and inputs it
//! must not change or must refuse.

use super::format;
use proptest::prelude::*;

#[track_caller]
fn formats_to(source: &str, expected: &str) {
    let formatted = format(source).unwrap_or_else(|d| panic!("{}", crate::render_all(&[d], "t.mrsl", source)));
    assert_eq!(formatted, expected, "formatting:\n{source}");
    assert_eq!(format(&formatted).unwrap(), formatted, "formatting again");
}

#[test]
fn one_layout_whatever_the_input_layout() {
    let messy = "in   float3 normal ;uniform float gain=1.0;\n\n\n\nconst int N=4 ;\n\
                 float f( float x,float y ){ float z=x*y+ -x;\n\n\n z+=1.0; if(z>0.0)return z; else{return -z;}}\n\
                 coarse(4) effect float e{e=f(normal.x,gain);if(fwidth(e)>0.1)refine;}\n\
                 fine out float4 color=float4(float3(e),1.0);";
    formats_to(
        messy,
        "in float3 normal;\nuniform float gain = 1.0;\n\nconst int N = 4;\n\
         float f(float x, float y) {\n    float z = x * y + -x;\n\n    z += 1.0;\n    if (z > 0.0)\n        return z;\n    \
         else {\n        return -z;\n    }\n}\n\
         coarse(4) effect float e {\n    e = f(normal.x, gain);\n    if (fwidth(e) > 0.1) refine;\n}\n\
         fine out float4 color = float4(float3(e), 1.0);\n",
    );
}

#[test]
fn blocks_else_and_for_headers() {
    formats_to(
        "float f(float x) {\n\n    for(int i=0;i<4;i++){if(x>1.0){x-=1.0;}else if(x<0.0){x=0.0;}else{break;}}\n\
         for(;;)break; {x = 1.0;}\n\n  return x;\n\n}\n",
        "float f(float x) {\n    for (int i = 0; i < 4; i++) {\n        if (x > 1.0) {\n            x -= 1.0;\n        \
         } else if (x < 0.0) {\n            x = 0.0;\n        } else {\n            break;\n        }\n    }\n    \
         for (;;)\n        break;\n    {\n        x = 1.0;\n    }\n\n    return x;\n}\n",
    );
}

#[test]
fn comments_stay_where_they_were_written() {
    formats_to(
        "// header\n\n// before a\nin float a;   // after a\nin float bb; /* b */\n\n\n// alone\n\n\
         float f() { // after the brace\n    // inside\n    return 1.0;  // after return\n    // before the brace\n}\n\
         // at the end\n",
        "// header\n\n// before a\nin float a;   // after a\nin float bb;  /* b */\n\n// alone\n\n\
         float f() {  // after the brace\n    // inside\n    return 1.0;  // after return\n    // before the brace\n}\n\
         // at the end\n",
    );
    // Inside expressions, argument lists and declarations.
    formats_to(
        "fine out float4 c = float4(/* x */ 1.0, // first\n 2.0, 3.0 /* last */, 4.0);\n",
        "fine out float4 c = float4(\n    /* x */ 1.0,  // first\n    2.0,\n    3.0,\n    /* last */ 4.0);\n",
    );
    formats_to("in float a; /* one\n   two */ in float b;\n", "in float a;  /* one\n   two */\nin float b;\n");
    formats_to("/* only a comment */", "/* only a comment */\n");
    formats_to("", "");
    formats_to(" \n\n", "");
}

#[test]
fn long_lines_break_at_operators_and_between_arguments() {
    let long = "fine out float4 color = float4(normal.x * gain + normal.y * gain + normal.z * gain, \
                saturate(dot(normal, light)), 0.5);\n";
    formats_to(
        long,
        "fine out float4 color = float4(\n    normal.x * gain + normal.y * gain + normal.z * gain,\n    \
         saturate(dot(normal, light)),\n    0.5);\n",
    );
    let sum = format!("const float s = {};\n", ["alpha_value"; 12].join(" + "));
    formats_to(
        &sum,
        "const float s = alpha_value + alpha_value + alpha_value + alpha_value + alpha_value + alpha_value\n    \
         + alpha_value + alpha_value + alpha_value + alpha_value + alpha_value + alpha_value;\n",
    );
    // A call's only argument, itself a call, breaks inside: no staircase.
    let nested = format!("const float n = a(b(c({})));\n", ["long_argument_name"; 6].join(", "));
    formats_to(
        &nested,
        "const float n = a(b(c(\n    long_argument_name,\n    long_argument_name,\n    long_argument_name,\n    \
         long_argument_name,\n    long_argument_name,\n    long_argument_name)));\n",
    );
    formats_to(
        "fine out float v = flag_with_a_long_name ? first_value_with_a_long_name : second_value_with_a_long_name_too;\n",
        "fine out float v = flag_with_a_long_name\n    ? first_value_with_a_long_name\n    \
         : second_value_with_a_long_name_too;\n",
    );
}

#[test]
fn what_the_tree_does_not_record_is_kept_as_written() {
    // Literals, the author's parentheses, prefix steps.
    formats_to(
        "const float a = ((1e3 + 2.)) * (0x1Fu);\nfloat f(int i) { ++i; i--; return float(i); }\n",
        "const float a = ((1e3 + 2.)) * (0x1Fu);\nfloat f(int i) {\n    ++i;\n    i--;\n    return float(i);\n}\n",
    );
    // What would lex otherwise: `- -x` is not `--x`, `1 .x` is not the float `1.`.
    formats_to("const float b = - -x + + +y;\n", "const float b = - -x + + +y;\n");
    formats_to("const float c = 1 .x;\n", "const float c = (1).x;\n");
    // Attributes stay on their declaration's line.
    formats_to(
        "@key ( 0.4 )\nin float3 normal;\n@nearest() fine out float o=1.0;\n",
        "@key(0.4) in float3 normal;\n@nearest fine out float o = 1.0;\n",
    );
}

#[test]
fn a_syntax_error_is_the_parsers_diagnostic() {
    for source in ["in float3 normal\nin float x;", "fine out float4 c = float4(1.0;", "in float $;", "/* open"] {
        let error = format(source).unwrap_err();
        let parsed = crate::syntax::parse(source).unwrap_err();
        assert_eq!((error.code, &error.message, error.span()), (parsed.code, &parsed.message, parsed.span()));
    }
}

#[test]
fn nesting_past_the_limit_is_refused_without_overflowing() {
    let deep = format!("const float x = {}1.0;\n", "- ".repeat(super::MAX_DEPTH + 1));
    let error = crate::format(&deep).unwrap_err();
    assert_eq!(error.code, "E0602");
    let ok = format!("const float x = {}-1.0;\n", "- ".repeat(super::MAX_DEPTH - 2));
    assert_eq!(crate::format(&ok).unwrap(), ok);
}

#[test]
fn byte_order_marks_and_crlf_line_ends() {
    // The byte order mark stays (a file's encoding is its author's); line ends become `\n`.
    formats_to("\u{FEFF}in float a;\r\n\r\n\r\nin float b; // c\r\n", "\u{FEFF}in float a;\n\nin float b;  // c\n");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any text formats or is refused with a diagnostic, never a panic nor an
    /// internal error; what formats formats again to itself.
    #[test]
    fn never_panics_and_is_idempotent(source in "[a-z0-9 ;=+*(){},.\\n/\\-]{0,120}|(in|float|fine|out|=|;|\\(|\\)|/\\*|\\*/|//|\\n| )*") {
        match crate::format(&source) {
            Ok(formatted) => prop_assert_eq!(crate::format(&formatted).unwrap(), formatted),
            Err(d) => prop_assert!(d.severity != crate::Severity::Bug, "{}", d.message),
        }
    }
}

//! The generated TextMate grammar (`sourcegen.rs`) against the compiler: a
//! small TextMate tokenizer runs the committed grammar file, and every token
//! kind of the lexer, every type name, builtin, attribute and form of number
//! must come out with its scope, as must every token of every example
//! program, token by token beside the lexer.
//!
//! The tokenizer does what VS Code's does for the rules the grammar uses
//! (`match` with `captures`, `begin`/`end`, `include` of the repository):
//! at each position the pattern whose match starts first wins, the earlier
//! listed on a tie, and an open rule's `end` before its patterns.

use crate::sourcegen::{GRAMMAR, repository_root, scope};
use mrsl::vocabulary::{self, Class};
use regex::Regex;
use serde_json::Value;

/// A rule of the grammar, its includes resolved.
enum Rule {
    Match { regex: Regex, name: Option<String>, captures: Vec<(usize, String)> },
    Block { begin: Regex, end: Regex, name: String, delimiters: Option<String> },
}

/// A scoped stretch of a line: its byte range and its scopes, outermost first.
#[derive(Debug, Clone)]
struct Scoped {
    line: usize,
    start: usize,
    end: usize,
    scopes: Vec<String>,
}

struct Grammar {
    rules: Vec<Rule>,
}

fn captures(value: &Value) -> Vec<(usize, String)> {
    let Some(map) = value.as_object() else { return vec![] };
    map.iter().map(|(group, c)| (group.parse().unwrap(), c["name"].as_str().unwrap().to_string())).collect()
}

impl Grammar {
    fn load() -> Grammar {
        let text = std::fs::read_to_string(repository_root().join(GRAMMAR)).expect("the grammar is generated");
        let grammar: Value = serde_json::from_str(&text).unwrap();
        let mut rules = vec![];
        Self::resolve(&grammar, &grammar["patterns"], &mut rules);
        Grammar { rules }
    }

    fn resolve(grammar: &Value, patterns: &Value, rules: &mut Vec<Rule>) {
        for pattern in patterns.as_array().expect("a list of patterns") {
            let regex = |key: &str| Regex::new(pattern[key].as_str().unwrap()).expect("the `regex` crate reads it");
            let name = pattern["name"].as_str().map(str::to_string);
            if let Some(include) = pattern["include"].as_str() {
                let key = include.strip_prefix('#').expect("includes name the repository");
                Self::resolve(grammar, &grammar["repository"][key]["patterns"], rules);
            } else if pattern.get("match").is_some() {
                rules.push(Rule::Match { regex: regex("match"), name, captures: captures(&pattern["captures"]) });
            } else {
                assert_eq!(pattern["beginCaptures"], pattern["endCaptures"], "one scope for both delimiters");
                let delimiters = captures(&pattern["beginCaptures"]).into_iter().find(|(g, _)| *g == 0).map(|(_, n)| n);
                rules.push(Rule::Block { begin: regex("begin"), end: regex("end"), name: name.unwrap(), delimiters });
            }
        }
    }

    /// The scoped stretches of `source`, line by line, as an editor colours it.
    fn tokenize(&self, source: &str) -> Vec<Scoped> {
        let mut out = vec![];
        let mut open: Option<&Rule> = None;
        for (line_index, line) in source.lines().enumerate() {
            let mut push = |start, end, scopes: Vec<&str>| {
                if start < end {
                    out.push(Scoped {
                        line: line_index,
                        start,
                        end,
                        scopes: scopes.into_iter().map(String::from).collect(),
                    })
                }
            };
            let mut pos = 0;
            while pos <= line.len() {
                if let Some(Rule::Block { end, name, delimiters, .. }) = open {
                    // Inside a block comment only its end is looked for.
                    let Some(m) = end.find_at(line, pos) else {
                        push(pos, line.len(), vec![name]);
                        break;
                    };
                    push(pos, m.start(), vec![name]);
                    push(m.start(), m.end(), [name.as_str()].into_iter().chain(delimiters.as_deref()).collect());
                    pos = m.end();
                    open = None;
                    continue;
                }
                let first = self
                    .rules
                    .iter()
                    .filter_map(|rule| {
                        let regex = match rule {
                            Rule::Match { regex, .. } => regex,
                            Rule::Block { begin, .. } => begin,
                        };
                        Some((regex.captures_at(line, pos)?, rule))
                    })
                    .min_by_key(|(c, _)| c.get(0).unwrap().start());
                let Some((found, rule)) = first else { break };
                let whole = found.get(0).unwrap();
                match rule {
                    Rule::Match { name, captures, .. } => {
                        let outer: Vec<&str> = name.iter().map(String::as_str).collect();
                        push(whole.start(), whole.end(), outer.clone());
                        for (group, scope) in captures {
                            if let Some(c) = found.get(*group) {
                                push(c.start(), c.end(), outer.iter().copied().chain([scope.as_str()]).collect());
                            }
                        }
                    }
                    Rule::Block { name, delimiters, .. } => {
                        push(
                            whole.start(),
                            whole.end(),
                            [name.as_str()].into_iter().chain(delimiters.as_deref()).collect(),
                        );
                        open = Some(rule);
                    }
                }
                pos = whole.end().max(whole.start() + 1);
            }
        }
        out
    }

    /// The innermost scope given to exactly `line`'s bytes `start..end`, if any.
    fn scope_of(tokens: &[Scoped], line: usize, start: usize, end: usize) -> Option<&str> {
        tokens
            .iter()
            .filter(|t| t.line == line && t.start == start && t.end == end && !t.scopes.is_empty())
            .max_by_key(|t| t.scopes.len())
            .map(|t| t.scopes.last().unwrap().as_str())
    }

    /// The innermost scope of `text` as it stands alone after `before` on a line.
    fn scope_in(&self, before: &str, text: &str, after: &str) -> Option<String> {
        let tokens = self.tokenize(&format!("{before}{text}{after}"));
        Self::scope_of(&tokens, 0, before.len(), before.len() + text.len()).map(str::to_string)
    }
}

/// The scope family each class must get, whatever the generator chose within it.
fn family(class: Class) -> &'static str {
    match class {
        Class::Declaration | Class::Control => "keyword.",
        Class::Rate => "storage.modifier.",
        Class::Boolean => "constant.language.",
        Class::Operator(_) => "keyword.operator.",
        Class::Punctuation(_) => "punctuation.",
    }
}

#[test]
fn every_keyword_operator_and_punctuation_has_its_scope() {
    let grammar = Grammar::load();
    for word in vocabulary::words() {
        // Alone, and between names; a symbol also right between them
        // (`a<=b`: the longest operator wins).
        let keyword = word.text.starts_with(|c: char| c.is_ascii_alphabetic());
        let contexts: &[(&str, &str)] =
            if keyword { &[("", ""), ("a ", " b")] } else { &[("", ""), ("a ", " b"), ("a", "b")] };
        for &(before, after) in contexts {
            let scope = grammar.scope_in(before, word.text, after);
            assert_eq!(scope, Some(super::sourcegen::scope(word.class)), "`{before}{}{after}`", word.text);
            assert!(scope.unwrap().starts_with(family(word.class)));
        }
        if word.class == Class::Control || word.class == Class::Declaration {
            // Not inside a longer name.
            assert_eq!(grammar.scope_in("x", word.text, "_1"), None, "{}", word.text);
        }
    }
}

#[test]
fn every_type_builtin_and_attribute_has_its_scope() {
    let grammar = Grammar::load();
    for ty in vocabulary::types() {
        assert_eq!(grammar.scope_in("uniform ", ty, " x;").as_deref(), Some("storage.type.builtin.mrsl"), "{ty}");
        assert_eq!(grammar.scope_in("", ty, "(1.0)").as_deref(), Some("storage.type.builtin.mrsl"), "{ty}");
        assert_eq!(grammar.scope_in("uniform ", &format!("{ty}x"), " x;"), None, "{ty}x");
    }
    for builtin in vocabulary::builtins() {
        let expected = if builtin.derivative { "support.function.derivative" } else { "support.function.builtin" };
        let scope = grammar.scope_in("x = ", builtin.name, "(y);");
        assert_eq!(scope, Some(format!("{expected}.mrsl")), "{}", builtin.name);
        // A name that only starts like one is a call of the program's own function.
        let own = format!("{}_of", builtin.name);
        assert_eq!(grammar.scope_in("x = ", &own, "(y);").as_deref(), Some("entity.name.function.mrsl"));
    }
    for attribute in vocabulary::attributes() {
        let line = format!("@{}(0.4) in float3 n;", attribute.name);
        let tokens = grammar.tokenize(&line);
        let end = 1 + attribute.name.len();
        assert_eq!(Grammar::scope_of(&tokens, 0, 0, 1), Some("punctuation.definition.attribute.mrsl"), "{line}");
        assert_eq!(Grammar::scope_of(&tokens, 0, 1, end), Some("entity.other.attribute-name.mrsl"), "{line}");
    }
    assert_eq!(grammar.scope_in("@", "keys", " in float k;"), None, "not an attribute of the language");
}

#[test]
fn numbers_and_comments_have_their_scopes() {
    let grammar = Grammar::load();
    for form in vocabulary::NUMBER_FORMS {
        for (text, _) in form.examples {
            let scope = grammar.scope_in("x = -", text, ";").unwrap_or_else(|| panic!("{text} has no scope"));
            assert!(scope.starts_with("constant.numeric.") && scope.contains(form.name), "{text}: {scope}");
        }
    }
    let source = "float x = 1.0; // a float\n/* one\n   float two\n*/ in float3 n; /**/ uniform";
    let tokens = grammar.tokenize(source);
    let at = |line, start, end| Grammar::scope_of(&tokens, line, start, end);
    assert_eq!(at(0, 0, 5), Some("storage.type.builtin.mrsl"));
    assert_eq!(at(0, 15, 17), Some("punctuation.definition.comment.mrsl"));
    assert_eq!(at(0, 15, 25), Some("comment.line.double-slash.mrsl"));
    assert_eq!(at(1, 0, 2), Some("punctuation.definition.comment.mrsl"));
    assert_eq!(at(2, 0, 12), Some("comment.block.mrsl"), "a comment's own lines are comment only");
    assert_eq!(at(3, 0, 2), Some("punctuation.definition.comment.mrsl"));
    assert_eq!(at(3, 3, 5), Some("keyword.other.declaration.mrsl"), "the code after `*/`");
    assert_eq!(at(3, 18, 20), Some("punctuation.definition.comment.mrsl"), "an empty comment's end");
    assert_eq!(at(3, 21, 28), Some("keyword.other.declaration.mrsl"), "after an empty comment");
}

/// Lines of the examples, with the scope of chosen tokens.
#[test]
fn example_lines_have_the_expected_scopes() {
    let grammar = Grammar::load();
    let cases: [(&str, &[(&str, &str)]); 4] = [
        (
            "@key(0.4) @encoded(octahedral) in float3 normal;",
            &[
                ("@", "punctuation.definition.attribute"),
                ("key", "entity.other.attribute-name"),
                ("0.4", "constant.numeric.float"),
                ("in", "keyword.other.declaration"),
                ("float3", "storage.type.builtin"),
                (";", "punctuation.terminator.statement"),
            ],
        ),
        (
            "coarse(4) effect float shadow = saturate(dot(n, l)) * 0.5;",
            &[
                ("coarse", "storage.modifier.rate"),
                ("4", "constant.numeric.integer.decimal"),
                ("effect", "keyword.other.declaration"),
                ("saturate", "support.function.builtin"),
                ("*", "keyword.operator.arithmetic"),
            ],
        ),
        (
            "    if (fwidth_surface(diffuse) > 0.05) refine;",
            &[
                ("if", "keyword.control"),
                ("fwidth_surface", "support.function.derivative"),
                (">", "keyword.operator.comparison"),
                ("refine", "keyword.control"),
            ],
        ),
        (
            "for (int i = 0; i < 4; i++) { total += shade(lights[i]); }",
            &[
                ("for", "keyword.control"),
                ("int", "storage.type.builtin"),
                ("++", "keyword.operator.increment"),
                ("+=", "keyword.operator.assignment"),
                ("shade", "entity.name.function"),
                ("[", "punctuation.section.brackets.begin"),
            ],
        ),
    ];
    for (line, expected) in cases {
        let tokens = grammar.tokenize(line);
        for (text, scope) in expected {
            let start = line.find(text).unwrap();
            let found = Grammar::scope_of(&tokens, 0, start, start + text.len());
            assert_eq!(found, Some(format!("{scope}.mrsl").as_str()), "`{text}` in `{line}`");
        }
    }
}

/// The scope a token of an example must get, by what the lexer read; `None`
/// for a name of the program's own (plain, or a call).
fn expected_scope(kind: &str, text: &str, after_at: bool) -> Option<String> {
    if kind.ends_with("literal") {
        return Some("constant.numeric.".into());
    }
    if kind != "identifier" {
        let word = vocabulary::words().into_iter().find(|w| w.text == text).expect("a word of fixed text");
        return Some(scope(word.class));
    }
    if after_at && vocabulary::attributes().iter().any(|a| a.name == text) {
        return Some("entity.other.attribute-name.mrsl".into());
    }
    if vocabulary::types().contains(&text) {
        return Some("storage.type.builtin.mrsl".into());
    }
    vocabulary::builtins()
        .iter()
        .find(|b| b.name == text)
        .map(|b| if b.derivative { "support.function.derivative.mrsl" } else { "support.function.builtin.mrsl" }.into())
}

/// Every token of every example, as the lexer reads it, has the scope its
/// kind calls for, and nothing the grammar takes for a comment is a token.
#[test]
fn the_grammar_colours_every_example_as_the_lexer_reads_it() {
    let grammar = Grammar::load();
    let mut examples: Vec<_> = std::fs::read_dir(repository_root().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mrsl"))
        .collect();
    examples.sort();
    assert!(examples.len() >= 6);
    for path in examples {
        let source = std::fs::read_to_string(&path).unwrap();
        let tokens = grammar.tokenize(&source);
        let line_starts: Vec<usize> =
            std::iter::once(0).chain(source.match_indices('\n').map(|(i, _)| i + 1)).collect();
        let mut after_at = false;
        for token in mrsl::internals::Lexer::new(&source) {
            let (start, token, end) = token.expect("the examples lex");
            let line = line_starts.partition_point(|&s| s <= start) - 1;
            let (text, kind) = (&source[start..end], token.kind_name());
            let (from, to) = (start - line_starts[line], end - line_starts[line]);
            let found = Grammar::scope_of(&tokens, line, from, to);
            let name = path.file_name().unwrap().to_string_lossy();
            match expected_scope(kind, text, after_at) {
                Some(expected) => assert!(
                    found.is_some_and(|f| f.starts_with(&expected)),
                    "{name}:{}: `{text}` ({kind}) is {found:?}, not {expected}",
                    line + 1
                ),
                None => assert!(
                    found.is_none_or(|f| f == "entity.name.function.mrsl"),
                    "{name}:{}: the name `{text}` is {found:?}",
                    line + 1
                ),
            }
            let in_comment = tokens.iter().any(|t| {
                t.line == line && t.start < to && from < t.end && t.scopes.iter().any(|s| s.starts_with("comment"))
            });
            assert!(!in_comment, "{name}:{}: `{text}` is coloured as a comment", line + 1);
            after_at = text == "@";
        }
    }
}

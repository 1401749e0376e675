//! Every program in the top-level `examples/` folder compiles without
//! warnings to the full default kernel table, and its layout describes what
//! its source declares: the channels, uniforms, textures, samplers, effects
//! (with their rates) and outputs, by name and type, in declaration order;
//! the block modes' tile kernel evaluates each coarse effect once per sample.
//! The declarations are read from the source by a line scanner that shares
//! nothing with the compiler's parser.

use mrsl_abi::Rate;

#[test]
fn examples_compile_to_layouts_that_match_their_declarations() {
    let examples = crate::examples();
    assert!(examples.len() >= 6, "expected at least 6 example programs, found {}", examples.len());
    for (name, source) in examples {
        let options = mrsl::Options { file_name: name.clone(), ..mrsl::Options::default() };
        let program = mrsl::compile(&source, &options)
            .unwrap_or_else(|d| panic!("{name} should compile:\n{}", mrsl::render_all(&d, &name, &source)));
        assert!(
            program.warnings.is_empty(),
            "{name}: an example compiles without warnings:\n{}",
            mrsl::render_all(&program.warnings, &name, &source)
        );
        crate::assert_kernel_table(&name, &program);

        let declared = Declarations::scan(&source);
        assert!(!declared.outputs.is_empty(), "{name}: the scanner found no `fine out`; is it still reading the file?");
        let layout = &program.layout;
        let channels: Vec<Declared> = layout
            .channels
            .iter()
            .map(|c| Declared { name: c.name.clone(), ty: c.ty.to_string(), key: c.key.is_some() })
            .collect();
        assert_eq!(
            channels, declared.channels,
            "{name}: layout channels (name, type, is a key) against `in` declarations"
        );
        let uniforms: Vec<(String, String)> = layout
            .uniforms
            .iter()
            .flat_map(|block| &block.fields)
            .map(|f| (f.name.clone(), f.ty.to_string()))
            .collect();
        assert_eq!(uniforms, declared.uniforms, "{name}: layout uniform fields against `uniform` declarations");
        let textures: Vec<&str> = layout.textures.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(textures, declared.textures, "{name}: layout textures against `uniform texture2d`");
        let samplers: Vec<&str> = layout.samplers.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(samplers, declared.samplers, "{name}: layout samplers against `uniform sampler`");
        let outputs: Vec<(String, String)> =
            layout.outputs.iter().map(|o| (o.name.clone(), o.ty.to_string())).collect();
        assert_eq!(outputs, declared.outputs, "{name}: layout outputs against `fine out` declarations");
        let effects: Vec<(String, Rate, String)> =
            layout.effects.iter().map(|e| (e.name.clone(), e.rate, e.ty.to_string())).collect();
        assert_eq!(effects, declared.effects, "{name}: layout effects (name, rate, type) against their declarations");
        // The block modes' tile kernel evaluates every coarse effect once per sample.
        for e in layout.effects.iter().filter(|e| e.live && e.rate == Rate::Coarse) {
            assert_eq!(e.sample_evaluations, Some(1), "{name}: `{}` evaluations per sample in the tile kernel", e.name);
        }
    }
}

/// An `in` declaration: name, type, and whether it has `@key` or `@surface_key`.
#[derive(Debug, PartialEq)]
struct Declared {
    name: String,
    ty: String,
    key: bool,
}

/// The top-level declarations of a program, in source order.
#[derive(Debug, Default)]
struct Declarations {
    channels: Vec<Declared>,
    /// (name, type); an array's type is written `float4[16]`, as the layout writes it.
    uniforms: Vec<(String, String)>,
    textures: Vec<String>,
    samplers: Vec<String>,
    /// (name, rate, type) of every effect and output.
    effects: Vec<(String, Rate, String)>,
    /// (name, type) of every `fine out`.
    outputs: Vec<(String, String)>,
}

impl Declarations {
    /// Reads the declarations that start at the beginning of a line (the
    /// examples' style): `in`, `uniform`, `coarse effect` (or `coarse(4)`,
    /// `coarse(2)`), `fine effect` and
    /// `fine out`, each possibly after attributes such as `@key`.
    fn scan(source: &str) -> Declarations {
        let mut found = Declarations::default();
        for line in source.lines() {
            if line.starts_with(char::is_whitespace) {
                continue;
            }
            let code = line.split("//").next().unwrap();
            let (attributes, rest) = split_attributes(code);
            let words: Vec<&str> = rest.split_whitespace().collect();
            match words.as_slice() {
                ["in", ty, name, ..] => found.channels.push(Declared {
                    name: identifier(name),
                    ty: ty.to_string(),
                    key: attributes.contains(&"key") || attributes.contains(&"surface_key"),
                }),
                ["uniform", "texture2d", name, ..] => found.textures.push(identifier(name)),
                ["uniform", "sampler", name, ..] => found.samplers.push(identifier(name)),
                ["uniform", ty, name_and_rest @ ..] => {
                    let declarator = name_and_rest.join(" ");
                    let name = identifier(&declarator);
                    let ty = match declarator[name.len()..].trim_start().strip_prefix('[') {
                        Some(length) => format!("{ty}[{}]", length.split(']').next().unwrap().trim()),
                        None => ty.to_string(),
                    };
                    found.uniforms.push((name, ty));
                }
                ["coarse" | "coarse(4)" | "coarse(2)", "effect", ty, name, ..] => {
                    found.effects.push((identifier(name), Rate::Coarse, ty.to_string()))
                }
                ["fine", "effect", ty, name, ..] => found.effects.push((identifier(name), Rate::Fine, ty.to_string())),
                ["fine", "out", ty, name, ..] => {
                    found.effects.push((identifier(name), Rate::Out, ty.to_string()));
                    found.outputs.push((identifier(name), ty.to_string()));
                }
                _ => {}
            }
        }
        found
    }
}

/// Splits leading attributes (`@key`, `@key(0.1)`, `@nearest`) off a line:
/// their names, and the rest of the line.
fn split_attributes(mut line: &str) -> (Vec<&str>, &str) {
    let mut names = vec![];
    while let Some(after_at) = line.trim_start().strip_prefix('@') {
        let name_end = after_at.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(after_at.len());
        names.push(&after_at[..name_end]);
        line = &after_at[name_end..];
        if let Some(arguments) = line.strip_prefix('(') {
            line = &arguments[arguments.find(')').expect("attribute arguments are closed on their line") + 1..];
        }
    }
    (names, line)
}

/// The identifier at the start of `text` (`color` in `color{` or `light_pos[16];`).
fn identifier(text: &str) -> String {
    text.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect()
}

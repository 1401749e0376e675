//! `mrslc lsp` as an editor talks to it: the real binary, spoken to over
//! its standard input and output with the protocol's framing (lsp-server's
//! own `Message`), in one scripted session per test. The response-time
//! figure of README's "Editor setup" comes from
//! `cargo test -p mrslc --test lsp -- --nocapture response_times`, which
//! prints it (and asserts only what the answers say, never how fast).

use lsp_server::{Message, Notification, Request, RequestId, ResponseError};
use serde_json::{Value, json};
use std::io::BufReader;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

const URI: &str = "file:///work/shade.mrsl";

/// A program with a non-ASCII comment before a name on the same line.
const PROGRAM: &str = "\
@key(0.4) in float3 normal;
uniform float3 light = float3(0.0, 1.0, 0.0);
coarse effect float diffuse {
    diffuse = saturate(dot(normal, light));
    if (fwidth(diffuse) > 0.05) refine;
}
fine out float4 color = /* é😀 */ float4(float3(diffuse), 1.0);
";

/// A server and the messages it sent that nobody has read yet.
struct Client {
    child: Child,
    stdin: ChildStdin,
    messages: Receiver<Message>,
    next_id: i32,
}

impl Client {
    /// Starts `mrslc lsp` and initialises it, offering `encodings`; returns
    /// the client and the server's capabilities.
    fn start(encodings: &[&str]) -> (Client, Value) {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mrslc"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("mrslc lsp starts");
        let stdin = child.stdin.take().unwrap();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let (sender, messages) = channel();
        std::thread::spawn(move || {
            while let Ok(Some(message)) = Message::read(&mut stdout) {
                if sender.send(message).is_err() {
                    break;
                }
            }
        });
        let mut client = Client { child, stdin, messages, next_id: 0 };
        let init = json!({ "capabilities": { "general": { "positionEncodings": encodings } } });
        let capabilities = client.request("initialize", init).expect("initialize succeeds");
        client.notify("initialized", json!({}));
        (client, capabilities["capabilities"].clone())
    }

    fn send(&mut self, message: Message) {
        message.write(&mut self.stdin).expect("the server reads its input");
    }

    fn next(&self) -> Message {
        match self.messages.recv_timeout(Duration::from_secs(30)) {
            Ok(message) => message,
            Err(RecvTimeoutError::Timeout) => panic!("the server said nothing for 30 s"),
            Err(RecvTimeoutError::Disconnected) => panic!("the server closed its output"),
        }
    }

    fn request(&mut self, method: &str, params: Value) -> Result<Value, ResponseError> {
        self.next_id += 1;
        let id = RequestId::from(self.next_id);
        self.send(Message::Request(Request::new(id.clone(), method.into(), params)));
        loop {
            if let Message::Response(response) = self.next()
                && response.id == id
            {
                return response.response_result;
            }
        }
    }

    /// The result of a request that must succeed.
    fn ask(&mut self, method: &str, params: Value) -> Value {
        self.request(method, params).unwrap_or_else(|e| panic!("{method} failed: {e:?}"))
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(Message::Notification(Notification::new(method.into(), params)));
    }

    /// Opens or changes the document to `text`; returns the diagnostics published for it.
    fn set_text(&mut self, text: &str, version: i32) -> Vec<Value> {
        if version == 1 {
            let document = json!({ "uri": URI, "languageId": "mrsl", "version": 1, "text": text });
            self.notify("textDocument/didOpen", json!({ "textDocument": document }));
        } else {
            let document = json!({ "uri": URI, "version": version });
            self.notify(
                "textDocument/didChange",
                json!({ "textDocument": document, "contentChanges": [{ "text": text }] }),
            );
        }
        loop {
            if let Message::Notification(n) = self.next()
                && n.method == "textDocument/publishDiagnostics"
            {
                return n.params["diagnostics"].as_array().cloned().unwrap_or_default();
            }
        }
    }

    /// Shuts the server down as an editor does; it exits with status 0.
    fn finish(mut self) {
        assert_eq!(self.ask("shutdown", Value::Null), Value::Null);
        self.notify("exit", Value::Null);
        let status = self.child.wait().expect("the server exits");
        assert!(status.success(), "{status}");
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `{ textDocument, position }` at the `nth` occurrence of `needle` in
/// `text`, `into` characters into it, with UTF-16 columns.
fn at(text: &str, needle: &str, nth: usize, into: usize) -> Value {
    let offset = text.match_indices(needle).nth(nth).unwrap_or_else(|| panic!("`{needle}` #{nth}")).0 + into;
    let line = text[..offset].matches('\n').count();
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let character = text[line_start..offset].encode_utf16().count();
    json!({ "textDocument": { "uri": URI }, "position": { "line": line, "character": character } })
}

fn labels(items: &Value) -> Vec<String> {
    let items = items.get("items").unwrap_or(items);
    items.as_array().unwrap().iter().map(|i| i["label"].as_str().unwrap().to_string()).collect()
}

#[test]
fn a_scripted_session() {
    let (mut client, capabilities) = Client::start(&["utf-16"]);
    assert_eq!(capabilities["positionEncoding"], "utf-16");
    assert!(client.set_text(PROGRAM, 1).is_empty(), "the program is valid");

    // An edit with a GLSL type: the diagnostic, its code and its help, and the quick fix.
    let broken = PROGRAM.replace("float4(float3(diffuse)", "float4(vec3(diffuse)");
    let diagnostics = client.set_text(&broken, 2);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    let d = &diagnostics[0];
    assert_eq!(d["code"], "E0100", "a call of `vec3`: an unknown function");
    assert!(d["message"].as_str().unwrap().contains("help: mrsl writes `float3`"), "{d}");
    // The column counts the comment's é as one unit and 😀 as two.
    let vec3 = at(&broken, "vec3", 0, 0)["position"].clone();
    assert_eq!(d["range"]["start"], vec3);
    let actions = client.ask(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": URI }, "range": d["range"], "context": { "diagnostics": [d] } }),
    );
    assert_eq!(actions[0]["title"], "Replace `vec3` with `float3`");
    let edit = &actions[0]["edit"]["changes"][URI][0];
    assert_eq!((&edit["newText"], &edit["range"]), (&json!("float3"), &d["range"]));

    // While the error stands, an effect's hover shows its facts from before the edit.
    let stale = client.ask("textDocument/hover", at(&broken, "diffuse", 0, 0));
    let stale = stale["contents"]["value"].as_str().unwrap();
    assert!(stale.contains("operations per evaluation") && stale.contains("last version without errors"), "{stale}");

    assert!(client.set_text(PROGRAM, 3).is_empty());
    let hover = client.ask("textDocument/hover", at(PROGRAM, "diffuse", 3, 2));
    let markdown = hover["contents"]["value"].as_str().unwrap();
    let facts = mrsl::analyze(PROGRAM).effects.into_iter().find(|e| e.name == "diffuse").unwrap();
    let operations = facts.layout.unwrap().operations.unwrap();
    for expected in [
        "coarse effect float diffuse",
        "rate `coarse`",
        &format!("{operations} operations"),
        "refined by keys",
        "fwidth(diffuse) > 0.05",
    ] {
        assert!(markdown.contains(expected), "`{expected}` in the hover:\n{markdown}");
    }
    // The last `diffuse`, after the comment: its range counts UTF-16 units.
    assert_eq!(hover["range"]["start"], at(PROGRAM, "diffuse", 3, 0)["position"]);
    let builtin = client.ask("textDocument/hover", at(PROGRAM, "saturate", 0, 1));
    assert!(builtin["contents"]["value"].as_str().unwrap().contains("saturate"), "{builtin}");

    let definition = client.ask("textDocument/definition", at(PROGRAM, "diffuse", 3, 0));
    assert_eq!(definition["range"]["start"], at(PROGRAM, "diffuse", 0, 0)["position"]);
    let mut references = at(PROGRAM, "normal", 1, 0);
    references["context"] = json!({ "includeDeclaration": true });
    let references = client.ask("textDocument/references", references);
    assert_eq!(references.as_array().unwrap().len(), 2, "{references}");

    let completion = labels(&client.ask("textDocument/completion", at(PROGRAM, "saturate", 0, 0)));
    for expected in ["normal", "light", "diffuse", "saturate", "fwidth", "float3", "refine"] {
        assert!(completion.contains(&expected.to_string()), "`{expected}` in {completion:?}");
    }
    let attributes = labels(&client.ask("textDocument/completion", at(PROGRAM, "key", 0, 0)));
    assert!(attributes.contains(&"key".into()) && attributes.contains(&"background".into()), "{attributes:?}");
    let channels = labels(&client.ask("textDocument/completion", at(PROGRAM, "normal", 0, 0)));
    assert!(channels.contains(&"position".into()) && channels.contains(&"albedo".into()), "{channels:?}");

    let symbols = client.ask("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let names: Vec<&str> = symbols.as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["normal", "light", "diffuse", "color"]);
    let whole = json!({ "start": { "line": 0, "character": 0 }, "end": { "line": 99, "character": 0 } });
    let hints = client.ask("textDocument/inlayHint", json!({ "textDocument": { "uri": URI }, "range": whole }));
    assert_eq!(hints[0]["label"], format!("{operations} ops"), "{hints}");
    assert_eq!(hints[0]["position"], at(PROGRAM, "diffuse", 0, "diffuse".len())["position"]);
    assert_eq!(hints.as_array().unwrap().len(), 2, "the effect and the output: {hints}");

    // Formatting: one edit of the whole text to `mrslc fmt`'s layout; none when formatted.
    let messy = PROGRAM.replace("uniform float3 light", "uniform   float3   light");
    client.set_text(&messy, 4);
    let document = json!({ "textDocument": { "uri": URI }, "options": { "tabSize": 4, "insertSpaces": true } });
    let edits = client.ask("textDocument/formatting", document.clone());
    let formatted = mrsl::format(&messy).unwrap();
    assert!(formatted.contains("uniform float3 light"), "{formatted}");
    assert_eq!(edits.as_array().unwrap().len(), 1, "{edits}");
    assert_eq!(
        (&edits[0]["newText"], &edits[0]["range"]["start"]),
        (&json!(formatted), &json!({ "line": 0, "character": 0 }))
    );
    client.set_text(&formatted, 5);
    assert_eq!(client.ask("textDocument/formatting", document), json!([]));
    client.set_text(PROGRAM, 6);

    // What a client may send wrong: the server answers and goes on.
    let mut elsewhere = at(PROGRAM, "diffuse", 0, 0);
    elsewhere["textDocument"]["uri"] = json!("file:///nowhere.mrsl");
    assert_eq!(client.ask("textDocument/hover", elsewhere), Value::Null);
    assert!(client.request("textDocument/hover", json!({ "nonsense": 1 })).is_err());
    assert!(client.request("workspace/unheardOf", json!({})).is_err());
    let past_the_end = json!({ "textDocument": { "uri": URI }, "position": { "line": 999, "character": 999 } });
    assert!(client.request("textDocument/completion", past_the_end).is_ok());
    client.finish();
}

/// A client that offers UTF-8 gets byte columns.
#[test]
fn utf8_columns_when_the_client_offers_them() {
    let (mut client, capabilities) = Client::start(&["utf-8", "utf-16"]);
    assert_eq!(capabilities["positionEncoding"], "utf-8");
    client.set_text(PROGRAM, 1);
    let offset = PROGRAM.rfind("diffuse").unwrap();
    let line_start = PROGRAM[..offset].rfind('\n').unwrap() + 1;
    let position = json!({ "line": 6, "character": offset - line_start });
    let hover = client.ask("textDocument/hover", json!({ "textDocument": { "uri": URI }, "position": position }));
    assert_eq!(hover["range"]["start"], position);
    client.finish();
}

/// Prints the median response time of diagnostics (an edit), hover and
/// completion on examples/sponza_lights.mrsl: the figure README quotes.
#[test]
fn response_times_on_sponza_lights() {
    let source =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/sponza_lights.mrsl")).unwrap();
    let (mut client, _) = Client::start(&["utf-16"]);
    assert!(client.set_text(&source, 1).is_empty());
    let rounds = 30;
    let median = |mut times: Vec<Duration>| {
        times.sort();
        times[times.len() / 2]
    };
    let mut edits = vec![];
    let mut hovers = vec![];
    let mut completions = vec![];
    for round in 0..rounds {
        // Alternate two texts, so that every edit is analysed afresh.
        let text = if round % 2 == 0 { source.replace("light_floor)", "light_floor )") } else { source.clone() };
        let start = Instant::now();
        assert!(client.set_text(&text, 2 + round).is_empty());
        edits.push(start.elapsed());
        let start = Instant::now();
        let hover = client.ask("textDocument/hover", at(&text, "float3 lights {", 0, 8));
        hovers.push(start.elapsed());
        assert!(hover["contents"]["value"].as_str().unwrap().contains("operations per evaluation"), "{hover}");
        let start = Instant::now();
        let completion = client.ask("textDocument/completion", at(&text, "sum += light_color", 0, 0));
        completions.push(start.elapsed());
        assert!(labels(&completion).contains(&"to_light".to_string()));
    }
    println!(
        "sponza_lights.mrsl, median of {rounds}: diagnostics after an edit {:.1} ms, hover {:.1} ms, completion {:.1} ms",
        median(edits).as_secs_f64() * 1e3,
        median(hovers).as_secs_f64() * 1e3,
        median(completions).as_secs_f64() * 1e3,
    );
    client.finish();
}

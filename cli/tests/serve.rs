//! `mrslc serve` as the playground talks to it: the real binary on a free
//! port of 127.0.0.1 (read from the line it prints), spoken to over raw
//! HTTP/1.1 on a `TcpStream` (so that a `..` path reaches the server as
//! written, which HTTP clients would normalise). One server serves every
//! test and is killed at the end, also when a test fails. The export test
//! needs a GPU adapter: without one it is reported as skipped (ignored),
//! with the reason printed; with `CI=true` a missing adapter is a failure.

use libtest_mimic::{Arguments, Trial};
use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::Duration;

type Test = fn(&Server);

const TESTS: &[(&str, Test)] = &[
    ("the_page_and_its_files_are_served", the_page_and_its_files_are_served),
    ("examples_and_scenes_are_listed", examples_and_scenes_are_listed),
    ("a_program_compiles_to_its_kernels_and_layout", a_program_compiles_to_its_kernels_and_layout),
    ("a_broken_program_gets_its_diagnostics_with_spans", a_broken_program_gets_its_diagnostics_with_spans),
    ("malformed_requests_are_400_with_serdes_message", malformed_requests_are_400_with_serdes_message),
    ("a_10_mb_program_is_413_and_the_server_goes_on", a_10_mb_program_is_413_and_the_server_goes_on),
    ("paths_outside_the_served_directory_are_400", paths_outside_the_served_directory_are_400),
    ("unknown_modes_and_scenes_are_400", unknown_modes_and_scenes_are_400),
    ("the_editor_gets_hover_and_completion", the_editor_gets_hover_and_completion),
];

/// Needs an adapter.
const GPU_TESTS: &[(&str, Test)] =
    &[("an_export_of_the_demo_serves_its_files", an_export_of_the_demo_serves_its_files)];

fn main() {
    let args = Arguments::from_args();
    let gpu = gpu_available();
    let server = Arc::new(Server::start());
    let mut trials: Vec<Trial> = vec![];
    for &(name, test) in TESTS {
        let server = server.clone();
        trials.push(Trial::test(name, move || {
            test(&server);
            Ok(())
        }));
    }
    for &(name, test) in GPU_TESTS {
        let server = server.clone();
        trials.push(match gpu {
            Ok(()) => Trial::test(name, move || {
                test(&server);
                Ok(())
            }),
            Err(_) => Trial::test(name, || Ok(())).with_ignored_flag(true),
        });
    }
    let conclusion = libtest_mimic::run(&args, trials);
    // The trials (and their handles on the server) are gone: this kills it.
    drop(server);
    conclusion.exit();
}

/// Whether the server will find an adapter (as it looks for one).
fn gpu_available() -> Result<(), String> {
    // SAFETY: no other thread exists yet.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    match mrsl_lab::gpu::Gpu::new() {
        Ok(_) => Ok(()),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => panic!("CI=true but no GPU adapter: {e}"),
        Err(e) => {
            println!("SKIPPING {} serve tests (reported as ignored below): no GPU adapter ({e})", GPU_TESTS.len());
            Err(e.to_string())
        }
    }
}

/// The running server; dropping it kills the process.
struct Server {
    child: Child,
    /// `127.0.0.1:PORT`.
    address: String,
}

impl Server {
    fn start() -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mrslc"))
            .args(["serve", "--port", "0"])
            .stdout(Stdio::piped())
            .spawn()
            .expect("mrslc serve starts");
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = BufReader::new(stdout).read_line(&mut line);
            let _ = tx.send(line);
        });
        // Killed by the guard if the line never comes.
        let mut server = Server { child, address: String::new() };
        let line = rx.recv_timeout(Duration::from_secs(60)).expect("mrslc serve prints its address");
        let url = line.trim().strip_prefix("playground: http://").unwrap_or_else(|| panic!("printed {line:?}"));
        server.address = url.trim_end_matches('/').to_string();
        assert!(server.address.starts_with("127.0.0.1:"), "{line}");
        server
    }

    /// Sends one request as written (`target` unchanged); returns the
    /// status, the headers (lower-case names) and the body.
    fn request(&self, method: &str, target: &str, body: &[u8]) -> Reply {
        let mut stream = TcpStream::connect(&self.address).expect("the server accepts");
        stream.set_read_timeout(Some(Duration::from_secs(300))).unwrap();
        let head = format!(
            "{method} {target} HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
            self.address,
            body.len()
        );
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(body).expect("the server reads the whole body");
        let mut raw = vec![];
        stream.read_to_end(&mut raw).expect("the server answers");
        Reply::parse(&raw)
    }

    fn get(&self, target: &str) -> Reply {
        self.request("GET", target, b"")
    }

    fn post(&self, target: &str, body: &Value) -> Reply {
        self.request("POST", target, body.to_string().as_bytes())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

struct Reply {
    status: u16,
    headers: Vec<(String, String)>,
    body: Vec<u8>,
}

impl Reply {
    fn parse(raw: &[u8]) -> Reply {
        let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a complete response head");
        let head = String::from_utf8_lossy(&raw[..split]).into_owned();
        let mut lines = head.split("\r\n");
        let status = lines.next().unwrap().split(' ').nth(1).unwrap().parse().unwrap();
        let headers: Vec<(String, String)> = lines
            .filter_map(|l| l.split_once(':'))
            .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
            .collect();
        let mut body = raw[split + 4..].to_vec();
        if headers.iter().any(|(n, v)| n == "transfer-encoding" && v.contains("chunked")) {
            body = dechunk(&body);
        }
        Reply { status, headers, body }
    }

    fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    fn json(&self) -> Value {
        serde_json::from_slice(&self.body).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&self.body)))
    }

    /// The error message of a refusal with `status`.
    fn error(&self, status: u16) -> String {
        assert_eq!(self.status, status, "{}", String::from_utf8_lossy(&self.body));
        assert_eq!(self.header("content-type"), Some("application/json"));
        self.json()["error"].as_str().expect("an error message").to_string()
    }
}

fn dechunk(mut body: &[u8]) -> Vec<u8> {
    let mut out = vec![];
    loop {
        let end = body.windows(2).position(|w| w == b"\r\n").unwrap();
        let size = usize::from_str_radix(std::str::from_utf8(&body[..end]).unwrap().trim(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&body[end + 2..end + 2 + size]);
        body = &body[end + 4 + size..];
    }
}

fn source(example: &str) -> String {
    std::fs::read_to_string(format!("{}/../examples/{example}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn the_page_and_its_files_are_served(server: &Server) {
    let index = server.get("/");
    assert_eq!(index.status, 200);
    assert_eq!(index.header("content-type"), Some("text/html; charset=utf-8"));
    let page = String::from_utf8(index.body).unwrap();
    assert!(page.contains("src=\"/playground.js\""), "{page}");
    for (path, kind) in [("/playground.js", "text/javascript"), ("/playground.css", "text/css")] {
        let file = server.get(path);
        assert_eq!(file.status, 200, "{path}");
        assert!(file.header("content-type").unwrap().starts_with(kind), "{path}");
    }
    let missing = server.get("/nothing.js").error(404);
    assert!(missing.contains("/nothing.js"), "{missing}");
}

fn examples_and_scenes_are_listed(server: &Server) {
    let examples = server.get("/api/examples").json();
    let examples = examples.as_array().unwrap();
    assert_eq!(examples.len(), 10);
    for e in examples {
        let file = e["file"].as_str().unwrap();
        assert_eq!(e["source"].as_str().unwrap(), source(file), "{file}");
        assert_eq!(format!("{}.mrsl", e["name"].as_str().unwrap()), file);
    }
    let scene = |name: &str| examples.iter().find(|e| e["name"] == name).unwrap()["scene"].clone();
    assert_eq!(
        (scene("demo"), scene("sponza_lights"), scene("pbr_deferred")),
        (json!("demo"), json!("sponza"), json!("dungeon"))
    );
    let scenes = server.get("/api/scenes").json();
    assert_eq!(scenes, json!(mrsl_lab::scene::Scene::NAMES));
}

fn a_program_compiles_to_its_kernels_and_layout(server: &Server) {
    let all = server.post("/api/compile", &json!({ "source": source("demo.mrsl") }));
    assert_eq!(all.status, 200);
    let all = all.json();
    assert_eq!(all["ok"], true);
    assert_eq!(all["diagnostics"], json!([]));
    let kernels = all["kernels"].as_array().unwrap();
    assert_eq!(kernels.len(), 17, "every mode's kernels");
    let coarse = kernels.iter().find(|k| k["kind"] == "coarse" && k["block"] == 4).unwrap();
    assert_eq!(coarse["file"], "program.coarse.b4.wgsl");
    assert!(coarse["wgsl"].as_str().unwrap().contains("@compute"));
    // Every mode, the block modes once for GPUs and once for CPU devices.
    assert_eq!(all["layout"]["plan"]["modes"].as_array().unwrap().len(), 10);
    let one = server.post("/api/compile", &json!({ "source": source("demo.mrsl"), "modes": ["reference"] })).json();
    let kinds: Vec<&Value> = one["kernels"].as_array().unwrap().iter().map(|k| &k["kind"]).collect();
    assert_eq!(kinds, [&json!("reference")]);
    assert_eq!(one["kernels"][0]["block"], Value::Null);
}

/// The playground's editor help: a hover on an effect shows its rate and
/// cost, one on a builtin its doc; completion offers the names in scope, the
/// builtins and, after `@`, the attributes. Columns count UTF-16 units, as
/// the browser does (an `é` before a name on its line).
fn the_editor_gets_hover_and_completion(server: &Server) {
    let program = "in float3 normal;\n// notes\n/*é*/ coarse effect float d = saturate(normal.y);\nfine out float4 color = float4(d);\n";
    let at = |line: u32, character: u32| json!({ "source": program, "line": line, "character": character });
    let hover = server.post("/api/hover", &at(3, 31)).json();
    let text = hover["contents"]["value"].as_str().unwrap_or_default();
    assert!(text.contains("coarse effect float d") && text.contains("operations"), "{hover}");
    assert_eq!(hover["range"]["start"], json!({ "line": 3, "character": 31 }), "{hover}");
    // `saturate` starts at UTF-16 column 30 (byte 31: `é` is two bytes).
    let builtin = server.post("/api/hover", &at(2, 30)).json();
    assert!(builtin["contents"]["value"].as_str().unwrap_or_default().contains("saturate"), "{builtin}");
    assert_eq!(server.post("/api/hover", &at(1, 3)).json(), Value::Null, "a comment has no hover");
    let labels = |reply: Value| -> Vec<String> {
        reply.as_array().unwrap().iter().map(|item| item["label"].as_str().unwrap().to_string()).collect()
    };
    let names = labels(server.post("/api/complete", &at(3, 31)).json());
    for name in ["d", "normal", "saturate", "float3", "refine"] {
        assert!(names.iter().any(|n| n == name), "no `{name}` in {names:?}");
    }
    let source = format!("@{program}");
    let attributes =
        labels(server.post("/api/complete", &json!({ "source": source, "line": 0, "character": 1 })).json());
    assert!(attributes.iter().any(|a| a == "key") && !attributes.iter().any(|a| a == "normal"), "{attributes:?}");
    server.post("/api/hover", &json!({ "source": program })).error(400);
}

fn a_broken_program_gets_its_diagnostics_with_spans(server: &Server) {
    // A character of two bytes before the error: offsets are bytes, columns characters.
    let program = "// λ\nin float3 normal;\nfine out float4 color = float4(nope, 1.0);\n";
    let reply = server.post("/api/compile", &json!({ "source": program }));
    assert_eq!(reply.status, 200, "a program that does not compile is not an HTTP error");
    let reply = reply.json();
    assert_eq!((&reply["ok"], &reply["kernels"], &reply["layout"]), (&json!(false), &json!([]), &Value::Null));
    let d = &reply["diagnostics"][0];
    assert_eq!((d["severity"].as_str(), d["code"].as_str()), (Some("error"), Some("E0100")));
    let start = program.find("nope").unwrap() as u64;
    let label = &d["labels"][0];
    assert_eq!(
        (&label["start"], &label["end"], &label["line"], &label["column"], &label["primary"]),
        (&json!(start), &json!(start + 4), &json!(3), &json!(32), &json!(true))
    );
    let rendered = d["rendered"].as_str().unwrap();
    assert!(rendered.starts_with("error[E0100]") && rendered.contains("program.mrsl:3:32"), "{rendered}");
    assert!(!rendered.contains('\u{1b}'), "no colour");
}

fn malformed_requests_are_400_with_serdes_message(server: &Server) {
    let broken = server.request("POST", "/api/compile", b"{\"source\": ").error(400);
    assert!(broken.starts_with("malformed request: EOF while parsing"), "{broken}");
    let missing = server.post("/api/compile", &json!({ "modes": ["reference"] })).error(400);
    assert!(missing.contains("missing field `source`"), "{missing}");
    let typed = server.post("/api/gbuffer", &json!({ "scene": "demo", "size": "big" })).error(400);
    assert!(typed.contains("invalid type: string \"big\""), "{typed}");
    let method = server.get("/api/compile").error(405);
    assert!(method.contains("method"), "{method}");
}

fn a_10_mb_program_is_413_and_the_server_goes_on(server: &Server) {
    let program = "// x\n".repeat(2 << 20);
    let body = json!({ "source": program }).to_string();
    assert!(body.len() >= 10_000_000);
    let error = server.request("POST", "/api/compile", body.as_bytes()).error(413);
    assert!(error.contains("over 1048576 bytes (1 MiB)"), "{error}");
    let after = server.post("/api/compile", &json!({ "source": source("demo.mrsl"), "modes": ["coarse4x4"] }));
    assert_eq!(after.json()["ok"], true);
}

fn paths_outside_the_served_directory_are_400(server: &Server) {
    for target in ["/../Cargo.toml", "/%2e%2e/Cargo.toml", "/api/gbuffer/x/..%2f..%2fCargo.toml", "/a/%2E%2E/b"] {
        assert_eq!(server.get(target).error(400), "path outside the served directory", "{target}");
    }
    assert_eq!(server.get("/").status, 200, "the server goes on");
}

fn unknown_modes_and_scenes_are_400(server: &Server) {
    let mode = server.post("/api/compile", &json!({ "source": "", "modes": ["coarse4x4", "coarse8x8"] })).error(400);
    assert!(mode.starts_with("unknown mode `coarse8x8` (known: reference, coarse2x2, coarse4x4"), "{mode}");
    let request = json!({ "scene": "atrium", "size": [32, 18], "source": source("demo.mrsl") });
    let scene = server.post("/api/gbuffer", &request).error(400);
    assert!(scene.contains("unknown scene `atrium`") && scene.contains("demo, gradient, steps"), "{scene}");
    // Scene files are not the playground's: a path would read the server's files.
    let file = server.post("/api/gbuffer", &json!({ "scene": "/etc/hall.toml", "size": [32, 18] })).error(400);
    assert!(file.contains("unknown scene"), "{file}");
    let size = server.post("/api/gbuffer", &json!({ "scene": "demo", "size": [1921, 1080] })).error(400);
    assert!(size.contains("at most 2073600 pixels"), "{size}");
    let broken = server.post("/api/gbuffer", &json!({ "scene": "demo", "size": [32, 18], "source": "fine out" }));
    let broken = broken.error(400);
    assert!(broken.starts_with("the program does not compile:\nerror[E0002]"), "{broken}");
}

fn an_export_of_the_demo_serves_its_files(server: &Server) {
    let request = json!({ "scene": "demo", "size": [32, 18], "source": source("demo.mrsl") });
    let reply = server.post("/api/gbuffer", &request);
    assert_eq!(reply.status, 200, "{}", String::from_utf8_lossy(&reply.body));
    let reply = reply.json();
    let (key, manifest) = (reply["key"].as_str().unwrap(), &reply["manifest"]);
    assert_eq!(reply["base"], format!("/api/gbuffer/{key}/"));
    assert_eq!((&manifest["format"], &manifest["size"]), (&json!("mrsl-gbuffer/1"), &json!([32, 18])));
    let channels = manifest["channels"].as_array().unwrap();
    let names: Vec<&str> = channels.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["position", "normal", "uv", "material", "depth", "albedo", "roughness", "metallic", "velocity"]);
    for c in channels {
        let bytes_per_texel = match c["format"].as_str().unwrap() {
            "rgba32float" => 16,
            "rg32float" => 8,
            "r32float" | "r32uint" => 4,
            other => panic!("{other}"),
        };
        let file = server.get(&format!("/api/gbuffer/{key}/{}", c["file"].as_str().unwrap()));
        assert_eq!(file.status, 200);
        assert_eq!(file.header("content-type"), Some("application/octet-stream"));
        assert_eq!(file.body.len(), 32 * 18 * bytes_per_texel, "{c}");
    }
    let served = server.get(&format!("/api/gbuffer/{key}/gbuffer.json")).json();
    assert_eq!(&served, manifest);
    let missing = server.get(&format!("/api/gbuffer/{key}/channel.nothing.bin")).error(404);
    assert!(missing.contains("channel.nothing.bin"), "{missing}");
    assert_eq!(server.get("/api/gbuffer/0-0/gbuffer.json").status, 404);
}

//! The rendered layout's last touches, line by line: trailing comments on
//! consecutive lines aligned, trailing whitespace removed, one line break
//! at the end.

/// The columns between the longest code of a run of lines and their comments.
const GAP: usize = 2;

/// Finishes the rendered text: `mark` starts each trailing comment.
pub fn finish(rendered: &str, mark: char) -> String {
    let lines: Vec<&str> = rendered.lines().map(str::trim_end).collect();
    let mut out: Vec<String> = Vec::with_capacity(lines.len());
    let mut i = 0;
    while i < lines.len() {
        let Some((code, _)) = split(lines[i], mark) else {
            out.push(lines[i].to_string());
            i += 1;
            continue;
        };
        // A run: consecutive lines with a trailing comment, at one indentation.
        let mut end = i + 1;
        while end < lines.len() && split(lines[end], mark).is_some_and(|(c, _)| indentation(c) == indentation(code)) {
            end += 1;
        }
        let run: Vec<(&str, &str)> = lines[i..end].iter().filter_map(|l| split(l, mark)).collect();
        let column = run.iter().map(|(code, _)| code.chars().count()).max().unwrap_or(0) + GAP;
        for (code, comment) in run {
            let pad = column - code.chars().count();
            out.push(if code.trim().is_empty() { comment.to_string() } else { format!("{code}{:pad$}{comment}", "") });
        }
        i = end;
    }
    while out.last().is_some_and(|l| l.is_empty()) {
        out.pop();
    }
    let start = out.iter().position(|l| !l.is_empty()).unwrap_or(out.len());
    let mut text = out[start..].join("\n");
    if !text.is_empty() {
        text.push('\n');
    }
    text
}

/// A line's code and its trailing comment, if it has one.
fn split(line: &str, mark: char) -> Option<(&str, &str)> {
    let at = line.find(mark)?;
    Some((line[..at].trim_end(), &line[at + mark.len_utf8()..]))
}

fn indentation(code: &str) -> usize {
    code.len() - code.trim_start().len()
}

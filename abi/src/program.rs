//! A compiled program as the runtime consumes it, and the files it is kept
//! in: `STEM.KIND.bB.wgsl` per block-sized kernel, `STEM.KIND.wgsl` for the
//! others, and `STEM.layout.json`.

use crate::{KernelKind, Layout};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One generated WGSL module.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Kernel {
    pub kind: KernelKind,
    /// Coarse block size: 2 or 4 for coarse and fine kernels, 2 for the
    /// dynamic mode's coarse kernel and 4 for its fine kernel, `None` otherwise.
    pub block_size: Option<u32>,
    pub wgsl: String,
}

impl Kernel {
    /// Every entry point of the module, in dispatch order.
    pub fn entry_points(&self) -> &'static [&'static str] {
        self.kind.entry_points()
    }

    /// The file name `mrslc compile` gives the kernel for a program called `stem`.
    pub fn file_name(&self, stem: &str) -> String {
        match self.block_size {
            Some(b) => format!("{stem}.{}.b{b}.wgsl", self.kind.name()),
            None => format!("{stem}.{}.wgsl", self.kind.name()),
        }
    }

    /// The kind and block size a kernel file name (without the stem) names:
    /// `coarse.b4.wgsl`, `reference.wgsl`.
    fn parse_file_name(rest: &str) -> Option<(KernelKind, Option<u32>)> {
        let rest = rest.strip_suffix(".wgsl")?;
        let (kind, block) = match rest.split_once(".b") {
            Some((kind, block)) => (kind, Some(block.parse().ok()?)),
            None => (rest, None),
        };
        Some((KernelKind::from_name(kind)?, block))
    }
}

/// Kernels and layout: everything the runtime needs to run a program, and
/// exactly what `mrslc compile -o DIR` writes.
#[derive(Debug, Clone, PartialEq)]
pub struct CompiledProgram {
    /// Sorted by kind, then block size.
    pub kernels: Vec<Kernel>,
    pub layout: Layout,
}

/// Why a compiled program could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum ReadError {
    /// A file could not be read or listed.
    Io { path: PathBuf, message: String },
    /// The directory holds no `*.layout.json`.
    NoLayout { dir: PathBuf },
    /// The directory holds the layouts of several programs; name one.
    SeveralPrograms { dir: PathBuf, stems: Vec<String> },
    /// The layout is not valid JSON of a supported format.
    Layout { path: PathBuf, message: String },
    /// There is a layout but no kernel beside it.
    NoKernels { dir: PathBuf, stem: String },
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Io { path, message } => write!(f, "cannot read {}: {message}", path.display()),
            ReadError::NoLayout { dir } => write!(
                f,
                "{} holds no compiled program (no *.layout.json); write one with `mrslc compile PROGRAM -o {}`",
                dir.display(),
                dir.display()
            ),
            ReadError::SeveralPrograms { dir, stems } => {
                write!(f, "{} holds several compiled programs ({}); name one", dir.display(), stems.join(", "))
            }
            ReadError::Layout { path, message } => write!(f, "{} is not an mrsl layout: {message}", path.display()),
            ReadError::NoKernels { dir, stem } => {
                write!(f, "{} has {stem}.layout.json but no {stem}.*.wgsl kernels", dir.display())
            }
        }
    }
}

impl std::error::Error for ReadError {}

impl CompiledProgram {
    /// Assembles a program, sorting the kernels into their canonical order.
    pub fn new(mut kernels: Vec<Kernel>, layout: Layout) -> CompiledProgram {
        kernels.sort_by_key(|k| (k.kind, k.block_size));
        CompiledProgram { kernels, layout }
    }

    /// The kernel of `kind` for block size `block` (ignored by kinds that
    /// exist once per program).
    pub fn kernel(&self, kind: KernelKind, block: u32) -> Option<&Kernel> {
        self.kernels.iter().find(|k| k.kind == kind && (!kind.per_block_size() || k.block_size == Some(block)))
    }

    /// The files of the program called `stem`: (file name, contents), kernels first.
    pub fn files(&self, stem: &str) -> Vec<(String, String)> {
        let mut files: Vec<(String, String)> =
            self.kernels.iter().map(|k| (k.file_name(stem), k.wgsl.clone())).collect();
        files.push((format!("{stem}.layout.json"), self.layout.to_json()));
        files
    }

    /// Writes [`CompiledProgram::files`] into `dir` (which must exist) and returns their paths.
    pub fn write_dir(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, (PathBuf, std::io::Error)> {
        self.files(stem)
            .into_iter()
            .map(|(name, text)| {
                let path = dir.join(name);
                std::fs::write(&path, text).map(|()| path.clone()).map_err(|e| (path, e))
            })
            .collect()
    }

    /// Reads the program `mrslc compile -o DIR` wrote into `dir`. With `stem`
    /// `None`, the directory must hold exactly one `*.layout.json`.
    pub fn read_dir(dir: &Path, stem: Option<&str>) -> Result<CompiledProgram, ReadError> {
        let io = |path: &Path, e: std::io::Error| ReadError::Io { path: path.to_path_buf(), message: e.to_string() };
        let mut names = vec![];
        for entry in std::fs::read_dir(dir).map_err(|e| io(dir, e))? {
            let entry = entry.map_err(|e| io(dir, e))?;
            if let Ok(name) = entry.file_name().into_string() {
                names.push(name);
            }
        }
        names.sort();
        let stem = match stem {
            Some(stem) => stem.to_string(),
            None => {
                let stems: Vec<&str> = names.iter().filter_map(|n| n.strip_suffix(".layout.json")).collect();
                match stems.as_slice() {
                    [] => return Err(ReadError::NoLayout { dir: dir.to_path_buf() }),
                    [one] => one.to_string(),
                    several => {
                        return Err(ReadError::SeveralPrograms {
                            dir: dir.to_path_buf(),
                            stems: several.iter().map(|s| s.to_string()).collect(),
                        });
                    }
                }
            }
        };
        let layout_path = dir.join(format!("{stem}.layout.json"));
        let text = std::fs::read_to_string(&layout_path).map_err(|e| io(&layout_path, e))?;
        let layout = Layout::from_json(&text).map_err(|message| ReadError::Layout { path: layout_path, message })?;
        let mut kernels = vec![];
        for name in &names {
            let Some((kind, block_size)) =
                name.strip_prefix(stem.as_str()).and_then(|r| r.strip_prefix('.')).and_then(Kernel::parse_file_name)
            else {
                continue;
            };
            let path = dir.join(name);
            let wgsl = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
            kernels.push(Kernel { kind, block_size, wgsl });
        }
        if kernels.is_empty() {
            return Err(ReadError::NoKernels { dir: dir.to_path_buf(), stem });
        }
        Ok(CompiledProgram::new(kernels, layout))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_file_names_round_trip() {
        for kind in KernelKind::ALL {
            for block_size in [None, Some(2), Some(4)] {
                let kernel = Kernel { kind, block_size, wgsl: String::new() };
                let name = kernel.file_name("my.shader");
                let rest = name.strip_prefix("my.shader.").unwrap();
                assert_eq!(Kernel::parse_file_name(rest), Some((kind, block_size)), "{name}");
            }
        }
        assert_eq!(Kernel::parse_file_name("layout.json"), None);
        assert_eq!(Kernel::parse_file_name("bogus.wgsl"), None);
        assert_eq!(Kernel::parse_file_name("coarse.bx.wgsl"), None);
    }
}

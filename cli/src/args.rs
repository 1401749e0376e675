//! The arguments of `mrslc render` as the commands take them, and the
//! parsers clap uses for the values of the command line (`--mode`,
//! `--set`, `--size`).

use mrsl_runtime::Mode;
use std::path::PathBuf;

/// What `mrslc render` was asked to do.
pub struct RenderArgs {
    pub program: Option<PathBuf>,
    pub scene: String,
    pub modes: Vec<Mode>,
    /// `--size`, if given; else the scene file's size, else 960x540.
    pub size: Option<(u32, u32)>,
    pub sets: Vec<(String, Vec<f64>)>,
    pub output: Option<PathBuf>,
    pub heatmap: Option<PathBuf>,
    /// Where files without an explicit path (`-o`, `--heatmap`) go.
    pub out_dir: PathBuf,
    pub stats: bool,
    pub force_refine: bool,
    /// Compare each mode's first output with the reference: metrics and an error image.
    pub compare: bool,
    /// `--raw`: each output's texels beside its PNG.
    pub raw: bool,
    /// The hierarchical mode's similarity threshold.
    pub similarity: f32,
    /// The rate-image mode's rate source.
    pub rates: mrsl_runtime::rate_source::RateOptions,
    /// The rate-image mode at one rate everywhere instead of the rate source's.
    pub uniform_rate: Option<mrsl_abi::ShadingRate>,
    /// With `--frames`: whether the rate source reads the motion vectors.
    pub motion: bool,
    /// `--frames N`: N frames along the scene's camera path (see
    /// [`crate::frames`]) instead of a still frame.
    pub frames: Option<usize>,
    /// `--plan`: the block modes' plan to run instead of the device's own.
    pub plan: Option<mrsl_abi::Device>,
}

/// The modes of `--mode`, in the order given, each once.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeList(pub Vec<Mode>);

/// Parses `--mode`: a comma-separated list of mode names, where `all`
/// stands for every mode in its usual order; every unknown name is
/// reported at once.
pub fn parse_modes(text: &str) -> Result<ModeList, String> {
    let mut modes = vec![];
    let mut unknown = vec![];
    for name in text.split(',').map(str::trim) {
        let named: Vec<Mode> = match name {
            "all" => Mode::ALL.to_vec(),
            _ => match name.parse() {
                Ok(mode) => vec![mode],
                Err(_) => {
                    unknown.push(format!("`{name}`"));
                    continue;
                }
            },
        };
        for mode in named {
            if !modes.contains(&mode) {
                modes.push(mode);
            }
        }
    }
    let expected = format!("{}, or all", Mode::ALL.map(Mode::name).join(", "));
    match unknown.len() {
        0 => Ok(ModeList(modes)),
        1 => Err(format!("unknown mode {} (expected a comma-separated list of {expected})", unknown[0])),
        _ => Err(format!("unknown modes {} (expected a comma-separated list of {expected})", unknown.join(", "))),
    }
}

/// Parses `name=v1,v2,...`.
pub fn parse_set(text: &str) -> Result<(String, Vec<f64>), String> {
    let (name, values) = text.split_once('=').ok_or_else(|| format!("expected NAME=VALUE[,VALUE...], got `{text}`"))?;
    let values = values
        .split(',')
        .map(|v| match v.trim() {
            "true" => Ok(1.0),
            "false" => Ok(0.0),
            v => v.parse::<f64>().map_err(|_| format!("`{v}` is not a number (in `{text}`)")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((name.trim().to_string(), values))
}

/// Parses `WxH`.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{text}`"))?;
    let w: u32 = w.parse().map_err(|_| format!("bad width in `{text}`"))?;
    let h: u32 = h.parse().map_err(|_| format!("bad height in `{text}`"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size `{text}` must be between 1x1 and 16384x16384"));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_are_a_comma_list_or_all() {
        assert_eq!(parse_modes("coarse4x4"), Ok(ModeList(vec![Mode::Coarse4x4])));
        assert_eq!(
            parse_modes("hierarchical, reference"),
            Ok(ModeList(vec![Mode::Hierarchical, Mode::Reference])),
            "in the order given"
        );
        assert_eq!(parse_modes("all"), Ok(ModeList(Mode::ALL.to_vec())));
        // Each mode once, where it first appears.
        assert_eq!(
            parse_modes("dynamic,all,dynamic"),
            Ok(ModeList(vec![
                Mode::Dynamic,
                Mode::Reference,
                Mode::Coarse2x2,
                Mode::Coarse4x4,
                Mode::Hierarchical,
                Mode::Checkerboard,
                Mode::RateImage,
                Mode::MultiRate
            ]))
        );
    }

    #[test]
    fn unknown_modes_are_named_together() {
        assert_eq!(
            parse_modes("reference,coarse8x8"),
            Err("unknown mode `coarse8x8` (expected a comma-separated list of reference, coarse2x2, coarse4x4, \
                 dynamic, hierarchical, checkerboard, rate-image, multi-rate, or all)"
                .into())
        );
        let e = parse_modes("fast,reference,,slow").unwrap_err();
        assert!(e.starts_with("unknown modes `fast`, ``, `slow` (expected"), "{e}");
    }
}

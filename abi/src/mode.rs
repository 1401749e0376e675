//! The modes a program is dispatched in and the kernels each one needs: the
//! one table of mode → kernels that the compiler (which kernels to
//! generate), the plan (which passes to run) and the runtimes (which modes a
//! program supports) all read.

use crate::KernelKind;
use crate::geometry::{DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK};
use serde::{Deserialize, Serialize};

/// How a program is dispatched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Mode {
    /// Every effect per pixel.
    #[serde(rename = "reference")]
    Reference,
    /// One coarse sample per 2x2 block, refined per block.
    #[serde(rename = "coarse2x2")]
    Coarse2x2,
    /// One coarse sample per 4x4 block, refined per block.
    #[serde(rename = "coarse4x4")]
    Coarse4x4,
    /// He et al.'s DYNAMIC: 4x4 blocks; where refined, 2x2 blocks; where
    /// refined again, per pixel.
    #[serde(rename = "dynamic")]
    Dynamic,
    /// Mallett & Yuksel's DACS: every 4th pixel shaded, then four levels each
    /// interpolated from previous-level neighbours or shaded (compacted work lists).
    #[serde(rename = "hierarchical")]
    Hierarchical,
    /// The baseline DACS compares with: coarse effects shaded in half the 2x2
    /// quads (a checkerboard), reconstructed in the others; not adaptive.
    #[serde(rename = "checkerboard")]
    Checkerboard,
    /// Software variable-rate shading: coarse effects shaded at a per-tile
    /// rate (1x1 to 4x4, anisotropic ones included) read from an
    /// engine-supplied shading-rate image, refined inside a tile as in the
    /// block modes.
    #[serde(rename = "rate-image")]
    RateImage,
    /// Three rates in one frame: `coarse(4)` effects at 4x4 samples,
    /// `coarse(2)` and plain `coarse` ones at 2x2 samples, fine effects per
    /// pixel, each boundary refined and resampled as in the block modes.
    #[serde(rename = "multi-rate")]
    MultiRate,
}

/// A kernel as a mode names it: its kind and, for the kinds that exist per
/// block size, the block size (as in [`crate::Kernel::block_size`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct KernelRef {
    pub kind: KernelKind,
    pub block: Option<u32>,
}

impl KernelRef {
    pub const fn new(kind: KernelKind, block: Option<u32>) -> KernelRef {
        KernelRef { kind, block }
    }
}

impl std::fmt::Display for KernelRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.block {
            Some(b) if self.kind.per_block_size() => write!(f, "{b}x{b} {}", self.kind),
            _ => write!(f, "{}", self.kind),
        }
    }
}

const fn kernel(kind: KernelKind, block: Option<u32>) -> KernelRef {
    KernelRef::new(kind, block)
}

impl Mode {
    pub const ALL: [Mode; 8] = [
        Mode::Reference,
        Mode::Coarse2x2,
        Mode::Coarse4x4,
        Mode::Dynamic,
        Mode::Hierarchical,
        Mode::Checkerboard,
        Mode::RateImage,
        Mode::MultiRate,
    ];

    /// The name in messages, on the command line and in the plan.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Reference => "reference",
            Mode::Coarse2x2 => "coarse2x2",
            Mode::Coarse4x4 => "coarse4x4",
            Mode::Dynamic => "dynamic",
            Mode::Hierarchical => "hierarchical",
            Mode::Checkerboard => "checkerboard",
            Mode::RateImage => "rate-image",
            Mode::MultiRate => "multi-rate",
        }
    }

    /// The kernels the mode dispatches, with their block sizes: those of
    /// every plan it has (see [`crate::plan::Device`]).
    pub fn kernels(self) -> &'static [KernelRef] {
        use KernelKind as K;
        const REFERENCE: [KernelRef; 1] = [kernel(K::Reference, None)];
        // On a GPU the tile kernel (one dispatch); on a CPU device the coarse and fine kernels.
        const COARSE_2X2: [KernelRef; 3] =
            [kernel(K::Tile, Some(2)), kernel(K::Coarse, Some(2)), kernel(K::Fine, Some(2))];
        const COARSE_4X4: [KernelRef; 3] =
            [kernel(K::Tile, Some(4)), kernel(K::Coarse, Some(4)), kernel(K::Fine, Some(4))];
        // The 4x4 level is the ordinary 4x4 coarse kernel; the dynamic mode has its own fine kernel.
        const DYNAMIC: [KernelRef; 3] = [
            kernel(K::Coarse, Some(DYNAMIC_OUTER_BLOCK)),
            kernel(K::DynamicCoarse, Some(DYNAMIC_INNER_BLOCK)),
            kernel(K::DynamicFine, Some(DYNAMIC_OUTER_BLOCK)),
        ];
        const HIERARCHICAL: [KernelRef; 1] = [kernel(K::Hierarchical, None)];
        const CHECKERBOARD: [KernelRef; 1] = [kernel(K::Checkerboard, None)];
        const RATE_IMAGE: [KernelRef; 2] = [kernel(K::RateCoarse, None), kernel(K::RateFine, None)];
        // The 4x4 samples, their values resolved per pixel, the 2x2 samples, the pixels.
        const MULTI_RATE: [KernelRef; 4] = [
            kernel(K::MultiCoarse, Some(DYNAMIC_OUTER_BLOCK)),
            kernel(K::MultiResolve, Some(DYNAMIC_OUTER_BLOCK)),
            kernel(K::MultiCoarse, Some(DYNAMIC_INNER_BLOCK)),
            kernel(K::MultiFine, Some(DYNAMIC_INNER_BLOCK)),
        ];
        match self {
            Mode::Reference => &REFERENCE,
            Mode::Coarse2x2 => &COARSE_2X2,
            Mode::Coarse4x4 => &COARSE_4X4,
            Mode::Dynamic => &DYNAMIC,
            Mode::Hierarchical => &HIERARCHICAL,
            Mode::Checkerboard => &CHECKERBOARD,
            Mode::RateImage => &RATE_IMAGE,
            Mode::MultiRate => &MULTI_RATE,
        }
    }

    /// The (first) coarse block size, or `None` for per-pixel shading.
    pub fn block_size(self) -> Option<u32> {
        match self {
            Mode::Reference | Mode::Hierarchical | Mode::Checkerboard | Mode::RateImage => None,
            // Its levels differ per effect; its finest coarse grid is 2x2.
            Mode::MultiRate => None,
            Mode::Coarse2x2 => Some(2),
            Mode::Coarse4x4 => Some(4),
            Mode::Dynamic => Some(DYNAMIC_OUTER_BLOCK),
        }
    }

    /// The kernels of `modes` together, each once, in the canonical order
    /// of [`crate::CompiledProgram::kernels`] (by kind, then block size).
    pub fn kernels_of(modes: &[Mode]) -> Vec<KernelRef> {
        let mut kernels: Vec<KernelRef> = modes.iter().flat_map(|m| m.kernels().iter().copied()).collect();
        kernels.sort();
        kernels.dedup();
        kernels
    }
}

/// A mode name that names no mode.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownMode(pub String);

impl std::fmt::Display for UnknownMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = Mode::ALL.iter().map(|m| m.name()).collect();
        write!(f, "unknown mode `{}` (expected {})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownMode {}

impl std::str::FromStr for Mode {
    type Err = UnknownMode;
    fn from_str(s: &str) -> Result<Mode, UnknownMode> {
        Mode::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| UnknownMode(s.to_string()))
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_in_text_and_json() {
        for mode in Mode::ALL {
            assert_eq!(mode.name().parse::<Mode>(), Ok(mode));
            assert_eq!(serde_json::to_string(&mode).unwrap(), format!("\"{}\"", mode.name()));
        }
        assert_eq!("coarse8x8".parse::<Mode>(), Err(UnknownMode("coarse8x8".into())));
        assert!(UnknownMode("x".into()).to_string().contains("rate-image"));
    }

    #[test]
    fn every_kernel_kind_belongs_to_a_mode() {
        let all = Mode::kernels_of(&Mode::ALL);
        for kind in KernelKind::ALL {
            assert!(all.iter().any(|k| k.kind == kind), "{kind}");
        }
        assert!(all.windows(2).all(|w| w[0] < w[1]));
    }
}

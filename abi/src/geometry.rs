//! Dispatch geometry both sides must agree on: where coarse samples lie,
//! how many workgroups each kernel is dispatched with, and how the
//! hierarchical mode's levels, work lists and queues are laid out. The code
//! generator writes these numbers into the kernels and the runtime sizes its
//! buffers and dispatches from them.

/// Pixels per side of the square tile one fine, reference or final workgroup shades.
pub const TILE: u32 = 8;

/// Invocations of a per-pixel workgroup (one tile, one pixel each).
pub const PIXEL_WORKGROUP: u32 = TILE * TILE;

/// Pixels each invocation of a block mode's fine kernel (and of the dynamic
/// fine kernel) shades: two pixels of one block, which share its four
/// coarse samples, loaded once per lane.
pub const FINE_PIXELS_PER_LANE: u32 = 2;

/// Invocations of a block mode's or the dynamic mode's fine workgroup (one tile,
/// [`FINE_PIXELS_PER_LANE`] pixels each).
pub const FINE_WORKGROUP: u32 = PIXEL_WORKGROUP / FINE_PIXELS_PER_LANE;

/// Invocations of a tile workgroup (the block modes' tile kernel): one lane
/// per coarse sample of the tile while it shades them, then four groups of
/// [`FINE_WORKGROUP`] lanes, each over [`TILE`]² pixels at a time.
pub const TILE_LANES: u32 = 128;

/// Coarse samples per side of a tile of the tile kernel, the largest first:
/// the compiler takes the first whose workgroup memory fits
/// [`TILE_WORKGROUP_BYTES`] and whose tile is at least [`TILE`] pixels wide
/// (`mrsl_abi::TileLayout`). With 8, a tile holds 9x9 samples (its own and
/// the next tile's first row and column) on 128 lanes: one sample a lane.
pub const TILE_SAMPLES: [u32; 3] = [8, 4, 2];

/// The workgroup memory a tile kernel may use: WebGPU's default
/// `maxComputeWorkgroupStorageSize`, which every device grants.
pub const TILE_WORKGROUP_BYTES: u32 = 16384;

/// Workgroups of the tile kernel: one per `side` x `side` pixels.
pub fn tile_workgroups(size: (u32, u32), side: u32) -> (u32, u32) {
    (size.0.div_ceil(side), size.1.div_ceil(side))
}

/// Invocations per side of a coarse-sample workgroup (coarse kernels and the
/// hierarchical level-0 and classify entry points).
pub const COARSE_WORKGROUP: u32 = 8;

/// Invocations of a workgroup that shades a compacted work list (hierarchical `hier_shade_*`).
pub const WORK_LIST_WORKGROUP: u32 = 64;

/// Checkerboard `cb_shade`: shaded 2x2 quads per workgroup, along a row of quads.
pub const CHECKERBOARD_QUADS_PER_WORKGROUP: u32 = 16;

/// Block size of the dynamic mode's first level: the ordinary coarse kernel of this block size.
pub const DYNAMIC_OUTER_BLOCK: u32 = 4;

/// Block size of the dynamic mode's second level (`dynamic_coarse_main`), shaded
/// only inside refined [`DYNAMIC_OUTER_BLOCK`] blocks.
pub const DYNAMIC_INNER_BLOCK: u32 = 2;

/// Words after each record of the dynamic mode's second level: a validity tag,
/// so its interface records are `stride_words + DYNAMIC_TAG_WORDS` words.
pub const DYNAMIC_TAG_WORDS: u32 = 1;

/// Words per level in the hierarchical queue and indirect-argument buffers:
/// the queue's first word counts queued pixels; the arguments are x, y, z, unused.
pub const QUEUE_WORDS_PER_LEVEL: u32 = 4;

/// Levels of the hierarchical mode: level 0 (always shaded) and the four classified levels.
pub const HIERARCHICAL_LEVEL_COUNT: u32 = 5;

/// Bytes of the hierarchical queue buffer and of its indirect-argument buffer.
pub const HIERARCHICAL_QUEUE_BYTES: u64 = (HIERARCHICAL_LEVEL_COUNT * QUEUE_WORDS_PER_LEVEL * 4) as u64;

/// The largest storage binding the runtime relies on (WebGPU's default limit).
pub const MAX_STORAGE_BINDING_BYTES: u64 = 128 << 20;

/// The largest side of a 2D texture the runtime relies on (WebGPU's default
/// `maxTextureDimension2D`): the record texture's sample grid must fit it.
pub const MAX_TEXTURE_SIDE: u32 = 8192;

/// The most layers of a texture array the runtime relies on (WebGPU's
/// default `maxTextureArrayLayers`): the record texture's layers must fit it.
pub const MAX_TEXTURE_LAYERS: u32 = 256;

/// The largest image side the runtime accepts.
pub const MAX_SIDE: u32 = 16384;

/// The number of coarse samples along each axis for a `size` image and
/// block size `block`: sample `(i, j)` shades pixel `(min(i*B, W-1), min(j*B, H-1))`,
/// so the last row and column of pixels always have samples.
pub fn sample_grid(size: (u32, u32), block: u32) -> (u32, u32) {
    ((size.0 + block - 2) / block + 1, (size.1 + block - 2) / block + 1)
}

/// The rule of [`sample_grid`] as the layout JSON states it for engines.
pub const SAMPLE_GRID_RULE: &str = "nx * ny, nx = (W + B - 2) / B + 1, ny = (H + B - 2) / B + 1 (integer division); sample (i, j) shades pixel (min(i*B, W-1), min(j*B, H-1))";

/// Workgroups of a coarse kernel over the samples of block size `block`.
pub fn coarse_workgroups(size: (u32, u32), block: u32) -> (u32, u32) {
    let (nx, ny) = sample_grid(size, block);
    (nx.div_ceil(COARSE_WORKGROUP), ny.div_ceil(COARSE_WORKGROUP))
}

/// Workgroups of a per-pixel kernel: one per tile.
pub fn pixel_workgroups(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(TILE), size.1.div_ceil(TILE))
}

/// Pixels `start, start + step, start + 2 step, ...` along each axis: the
/// grid one hierarchical entry point is dispatched over (one invocation
/// each). With `odd_only`, only the points whose lattice coordinates (i, j)
/// have an odd sum: invocation (g, j) is point (2 g + (j + 1) mod 2, j), so
/// a dispatch is half as wide and no lane idles on an even point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lattice {
    pub start: u32,
    pub step: u32,
    pub odd_only: bool,
}

impl Lattice {
    /// Lattice points along an axis of `n` pixels.
    pub fn count(self, n: u32) -> u32 {
        if n > self.start { (n - self.start - 1) / self.step + 1 } else { 0 }
    }

    /// Lattice points of a `size` image (every point, `odd_only` or not).
    pub fn points(self, size: (u32, u32)) -> u64 {
        u64::from(self.count(size.0)) * u64::from(self.count(size.1))
    }

    /// Invocations along x and y: the points along each axis, along x half
    /// of them (rounded up) with `odd_only`.
    pub fn invocations(self, size: (u32, u32)) -> (u32, u32) {
        let x = self.count(size.0);
        (if self.odd_only { x.div_ceil(2) } else { x }, self.count(size.1))
    }

    /// Workgroups of [`COARSE_WORKGROUP`]² invocations covering the lattice (at least one).
    pub fn workgroups(self, size: (u32, u32)) -> (u32, u32) {
        let (x, y) = self.invocations(size);
        let groups = |n: u32| n.div_ceil(COARSE_WORKGROUP).max(1);
        (groups(x), groups(y))
    }
}

/// Level 0 of the hierarchical mode: every 4th pixel in both directions, always shaded.
pub const HIERARCHICAL_LEVEL0: Lattice = Lattice { start: 0, step: 4, odd_only: false };

/// The dispatch lattices of hierarchical levels 1 to 4. Levels 2 and 4 use
/// only the lattice points with an odd coordinate sum; the work lists still
/// reserve a word per point, so each list's capacity is its lattice's size.
pub const HIERARCHICAL_LEVELS: [Lattice; 4] = [
    Lattice { start: 2, step: 4, odd_only: false },
    Lattice { start: 0, step: 2, odd_only: true },
    Lattice { start: 1, step: 2, odd_only: false },
    Lattice { start: 0, step: 1, odd_only: true },
];

/// Words of the hierarchical work lists (levels 1 to 4 one after another).
pub fn work_list_words(size: (u32, u32)) -> u64 {
    HIERARCHICAL_LEVELS.iter().map(|l| l.points(size)).sum()
}

/// Byte offset of level `level`'s (1 to 4) indirect dispatch arguments.
pub fn indirect_args_offset(level: u32) -> u64 {
    u64::from(level * QUEUE_WORDS_PER_LEVEL * 4)
}

/// Pixels per side of the hierarchical mode's tiles, in a program with a
/// background rule: what one workgroup of level 0 covers. A tile whose
/// every pixel is background is left out of every level's dispatches and
/// shaded by `hier_background` alone.
pub const HIERARCHICAL_TILE: u32 = HIERARCHICAL_LEVEL0.step * COARSE_WORKGROUP;

/// The hierarchical tiles along x and y of a `size` image.
pub fn hierarchical_tile_grid(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(HIERARCHICAL_TILE), size.1.div_ceil(HIERARCHICAL_TILE))
}

/// Words of the hierarchical queue buffer that count the surface tiles (list
/// 0) and the background tiles (list 1): level 0's words, which count no
/// pixels (level 0 has no work list).
pub const HIERARCHICAL_TILE_COUNTS: [u32; 2] = [0, 1];

/// Words of the hierarchical indirect-argument buffer: per level 1 to 4 the
/// dispatch over its work list (at word `4 L`), per level 0 to 4 the
/// dispatch over the surface tiles (at `4 (5 + L)`), and the dispatch over
/// the background tiles (at 40).
pub const HIERARCHICAL_ARGUMENT_WORDS: u32 = (2 * HIERARCHICAL_LEVEL_COUNT + 1) * QUEUE_WORDS_PER_LEVEL;

/// Byte offset of the arguments of level `level`'s (0 to 4) dispatch over the surface tiles.
pub fn level_tile_args_offset(level: u32) -> u64 {
    u64::from((HIERARCHICAL_LEVEL_COUNT + level) * QUEUE_WORDS_PER_LEVEL * 4)
}

/// Byte offset of the arguments of the dispatch over the background tiles.
pub fn background_tile_args_offset() -> u64 {
    u64::from(2 * HIERARCHICAL_LEVEL_COUNT * QUEUE_WORDS_PER_LEVEL * 4)
}

/// Workgroups of [`COARSE_WORKGROUP`]² lanes per background tile: one lane per pixel.
pub const BACKGROUND_TILE_WORKGROUPS: (u32, u32) =
    (HIERARCHICAL_TILE / COARSE_WORKGROUP, HIERARCHICAL_TILE / COARSE_WORKGROUP);

/// Word of the work lists where the tile list starts: the back of level 4's
/// list, which it never reaches. Level 4 lists at most the pixels with an
/// odd coordinate sum, half its lattice's words rounded down, and the tiles
/// are never more than the other half (a test checks it), so the surface
/// tiles (from the front) and the background tiles (from the back) of the
/// tile list and level 4's pixels never share a word.
pub fn tile_list_offset(size: (u32, u32)) -> u64 {
    let (tx, ty) = hierarchical_tile_grid(size);
    work_list_words(size) - u64::from(tx) * u64::from(ty)
}

impl Lattice {
    /// Workgroups per hierarchical tile along x and y for a lattice whose
    /// step divides [`HIERARCHICAL_TILE`]: its points in a tile (half of
    /// them along x with `odd_only`) in workgroups of [`COARSE_WORKGROUP`]².
    pub fn workgroups_per_tile(self) -> (u32, u32) {
        let points = HIERARCHICAL_TILE / self.step;
        let x = if self.odd_only { points / 2 } else { points };
        (x / COARSE_WORKGROUP, points / COARSE_WORKGROUP)
    }
}

/// The block and dynamic fine kernels' tile lists: list 0 holds the surface
/// tiles, list 1 the background tiles. Their counters are a word each; their
/// indirect arguments (x, y, z, unused) lie [`QUEUE_WORDS_PER_LEVEL`] words
/// apart, laid out in rows as wide as the image's tiles
/// ([`pixel_workgroups`]): workgroup (x, y) shades entry `y * tiles_x + x`.
pub const TILE_LISTS: u32 = 2;

/// The tile list of the tiles with surface in them, which the main fine entry point shades.
pub const SURFACE_TILE_LIST: u32 = 0;

/// The tile list of the wholly-background tiles, which `fine_background` shades.
pub const BACKGROUND_TILE_LIST: u32 = 1;

/// Byte offset of tile list `list`'s (0 or 1) indirect dispatch arguments.
pub fn tile_args_offset(list: u32) -> u64 {
    u64::from(list * QUEUE_WORDS_PER_LEVEL * 4)
}

/// Rate-image mode: shading-rate tiles per side of one `rate_list` workgroup
/// (one invocation per tile).
pub const RATE_LIST_TILES: u32 = 8;

/// Rate-image mode: `rate_list` workgroups for a `size` image and `tile`-pixel tiles.
pub fn rate_list_workgroups(size: (u32, u32), tile: u32) -> (u32, u32) {
    let (tx, ty) = crate::shading_rate::rate_image_size(size, tile);
    (tx.div_ceil(RATE_LIST_TILES), ty.div_ceil(RATE_LIST_TILES))
}

/// Rate-image mode: words of the sample list. Every listed sample is a
/// distinct pixel (each is listed by the one tile that owns it), so the
/// list never holds more than one word per pixel.
pub fn rate_work_words(size: (u32, u32)) -> u64 {
    u64::from(size.0) * u64::from(size.1)
}

/// Rate-image mode: bytes of the counter buffer (word 0 counts listed
/// samples) and of the indirect arguments of `rate_coarse` (x, y, z, unused):
/// the workgroups are laid out `RATE_ARGS_MAX_X` wide and as many rows as needed.
pub const RATE_QUEUE_BYTES: u64 = (QUEUE_WORDS_PER_LEVEL * 4) as u64;

/// Rate-image mode: the widest indirect dispatch row (WebGPU's default
/// `max_compute_workgroups_per_dimension`).
pub const RATE_ARGS_MAX_X: u32 = 65535;

/// Checkerboard `cb_shade` workgroups: rows of quads, [`CHECKERBOARD_QUADS_PER_WORKGROUP`]
/// shaded quads per workgroup (half the quads of a row; all when `forced`).
pub fn checkerboard_workgroups(size: (u32, u32), forced: bool) -> (u32, u32) {
    let (quads_x, quads_y) = (size.0.div_ceil(2), size.1.div_ceil(2));
    let shaded_per_row = if forced { quads_x } else { quads_x.div_ceil(2) };
    (shaded_per_row.div_ceil(CHECKERBOARD_QUADS_PER_WORKGROUP).max(1), quads_y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hierarchical_levels_cover_every_pixel_once() {
        for size in [(1, 1), (2, 3), (7, 5), (16, 9), (33, 17)] {
            let mut shaded = vec![0u32; (size.0 * size.1) as usize];
            let mut mark = |x: u32, y: u32| shaded[(y * size.0 + x) as usize] += 1;
            for y in 0..HIERARCHICAL_LEVEL0.count(size.1) {
                for x in 0..HIERARCHICAL_LEVEL0.count(size.0) {
                    mark(x * 4, y * 4);
                }
            }
            // As the kernel maps invocations to points (`Lattice` docs).
            for level in &HIERARCHICAL_LEVELS {
                let (nx, ny) = level.invocations(size);
                for j in 0..ny {
                    for g in 0..nx {
                        let i = if level.odd_only { 2 * g + (j + 1) % 2 } else { g };
                        let (x, y) = (level.start + i * level.step, level.start + j * level.step);
                        if x < size.0 && y < size.1 {
                            mark(x, y);
                        }
                    }
                }
            }
            assert!(shaded.iter().all(|&n| n == 1), "{size:?}: {shaded:?}");
        }
    }

    /// The tile list fits the back of level 4's work list beside the most
    /// pixels level 4 can list, and a level's tile workgroups cover its
    /// points in a tile exactly.
    #[test]
    fn the_tile_list_fits_behind_level_four() {
        for w in 1..70 {
            for h in [1, 2, 3, 31, 32, 33, 65, 1080] {
                let level4 = HIERARCHICAL_LEVELS[3];
                let listed = level4.points((w, h)) / 2;
                let (tx, ty) = hierarchical_tile_grid((w, h));
                let start = tile_list_offset((w, h)) - (work_list_words((w, h)) - level4.points((w, h)));
                assert!(listed <= start, "{w}x{h}: level 4 lists up to {listed}, tiles start at {start}");
                assert!(u64::from(tx * ty) <= level4.points((w, h)));
            }
        }
        for level in std::iter::once(HIERARCHICAL_LEVEL0).chain(HIERARCHICAL_LEVELS) {
            let (x, y) = level.workgroups_per_tile();
            let points = u64::from(HIERARCHICAL_TILE / level.step).pow(2);
            let lanes = u64::from(x * y * COARSE_WORKGROUP * COARSE_WORKGROUP);
            assert_eq!(lanes, if level.odd_only { points / 2 } else { points }, "{level:?}");
        }
    }

    #[test]
    fn samples_reach_the_last_pixel() {
        for (w, b) in [(1, 2), (2, 2), (3, 2), (8, 4), (9, 4), (10, 4)] {
            let (nx, _) = sample_grid((w, 1), b);
            assert!(((nx - 1) * b).min(w - 1) == w - 1 && (nx < 2 || (nx - 2) * b < w - 1), "{w} {b}");
        }
    }
}

//! The pass plan ([`mrsl_abi::Plan`]) of the modes a program is compiled
//! for: for each mode its passes in dispatch order, what every binding of
//! every kernel's stage group holds, and how each runtime-owned resource is
//! sized. The kernels declare exactly these bindings (the contract test
//! checks it); the runtimes interpret the plan and restate none of it.

use mrsl_abi::geometry::{
    self, DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK, HIERARCHICAL_LEVEL0, HIERARCHICAL_LEVELS, QUEUE_WORDS_PER_LEVEL,
    WORK_LIST_WORKGROUP,
};
use mrsl_abi::plan::{
    BackgroundCounts, BindingType, Counts, Dispatch, Evaluations, Extent, ModePlan, Pass, PassBinding, Plan,
    ResourceDesc, ResourceId, SampleCount, Shape, Stage, Step, WorkListCounts, Workgroups,
};
use mrsl_abi::{Device, KernelKind, KernelRef, Layout, Mode, TextureFormat, entry};

/// The plan of `modes` (each once, in [`Mode::ALL`] order) for a program of `layout`.
pub fn build(layout: &Layout, modes: &[Mode]) -> Plan {
    let modes: Vec<ModePlan> = Mode::ALL
        .into_iter()
        .filter(|m| modes.contains(m))
        .flat_map(|mode| devices(mode).into_iter().map(move |device| mode_plan(layout, mode, device)))
        .collect();
    let mut ids: Vec<ResourceId> = modes.iter().flat_map(|m| m.resources()).filter(|id| !id.engine_bound()).collect();
    ids.sort();
    ids.dedup();
    let resources = ids.into_iter().map(|id| resource(layout, id)).collect();
    Plan { modes, resources, constants: Default::default() }
}

/// Sets every pass's `workgroup_bytes` from its kernel's, as validation measured them.
pub fn set_workgroup_bytes(plan: &mut Plan, kernels: &[(KernelRef, u32)]) {
    for step in plan.modes.iter_mut().flat_map(|m| m.steps.iter_mut()) {
        if let Step::Pass(pass) = step {
            pass.workgroup_bytes = kernels.iter().find(|(k, _)| *k == pass.kernel).map_or(0, |(_, bytes)| *bytes);
        }
    }
}

/// The kinds of device `mode` has a plan of its own for (`None`: one plan
/// for every device). The block modes run the tile kernel on GPUs and the
/// coarse and fine kernels on CPU devices, where they measured faster
/// (docs/eval/evaluation.md, "One tile kernel").
fn devices(mode: Mode) -> Vec<Option<Device>> {
    match mode {
        Mode::Coarse2x2 | Mode::Coarse4x4 => vec![Some(Device::Gpu), Some(Device::Cpu)],
        _ => vec![None],
    }
}

/// The steps and counts of one mode on `device`.
fn mode_plan(layout: &Layout, mode: Mode, device: Option<Device>) -> ModePlan {
    let mut steps = vec![Step::Clear { resource: ResourceId::Statistics }];
    let counts = match mode {
        Mode::Reference => {
            let reference = KernelRef::new(KernelKind::Reference, None);
            steps.push(pass(layout, "mrsl reference", Stage::Fine, reference, vec![tiles(entry::REFERENCE)]));
            Counts {
                samples: SampleCount::None,
                evaluations: Evaluations::EveryPixel,
                work_lists: None,
                background: None,
            }
        }
        Mode::Coarse2x2 | Mode::Coarse4x4 if device == Some(Device::Gpu) => tile_steps(layout, mode, &mut steps),
        Mode::Coarse2x2 | Mode::Coarse4x4 | Mode::Dynamic => block_steps(layout, mode, &mut steps),
        Mode::Hierarchical => hierarchical_steps(layout, &mut steps),
        Mode::Checkerboard => {
            let kernel = KernelRef::new(KernelKind::Checkerboard, None);
            let shade = dispatch(entry::CB_SHADE, Workgroups::CheckerboardQuads);
            let mut dispatches = vec![shade];
            dispatches.extend(pixel_dispatches(layout, &mut steps, entry::CB_FINAL));
            steps.push(pass(layout, "mrsl checkerboard", Stage::Fine, kernel, dispatches));
            Counts { samples: SampleCount::None, evaluations: Evaluations::Counted, work_lists: None, background: None }
        }
        Mode::RateImage => rate_image_steps(layout, &mut steps),
        Mode::MultiRate => multi_rate_steps(layout, &mut steps),
    };
    steps.push(Step::Readback { resource: ResourceId::Statistics, bytes: None });
    let mut counts = counts;
    // The reference counts nothing; the others count the background they skip.
    if let (Some((pixels, samples)), false) = (layout.background_counters(), mode == Mode::Reference) {
        let sampled = !matches!(counts.samples, SampleCount::None);
        counts.background = Some(BackgroundCounts { pixels, samples: sampled.then_some(samples) });
    }
    let used: Vec<KernelRef> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Pass(p) => Some(p.kernel),
            _ => None,
        })
        .collect();
    let kernels = mode.kernels().iter().copied().filter(|k| used.contains(k)).collect();
    ModePlan { mode, device, kernels, steps, counts }
}

/// The block modes: one dispatch of the tile kernel, a workgroup per tile
/// of the layout's `tile` samples per side.
fn tile_steps(layout: &Layout, mode: Mode, steps: &mut Vec<Step>) -> Counts {
    let block = mode.block_size().expect("block modes have a block size");
    let kernel = KernelRef::new(KernelKind::Tile, Some(block));
    let tiles = dispatch(entry::TILE, Workgroups::PixelTiles { side: layout.tile.side(block) });
    steps.push(pass(layout, "mrsl tiles", Stage::Fine, kernel, vec![tiles]));
    Counts {
        samples: SampleCount::Grid { block, counter: None },
        evaluations: Evaluations::SamplesAndCounted,
        work_lists: None,
        background: None,
    }
}

/// The block modes on CPU devices and the dynamic mode: the coarse samples
/// (their neighbour values first, when the program stores them), the
/// dynamic mode's 2x2 level, then the per-pixel pass.
fn block_steps(layout: &Layout, mode: Mode, steps: &mut Vec<Step>) -> Counts {
    let block = mode.block_size().expect("block modes have a block size");
    let samples = Workgroups::SampleGrid { block };
    let mut coarse = vec![];
    if layout.neighbours.words > 0 {
        coarse.push(dispatch(entry::COARSE_NEIGHBOURS, samples));
    }
    coarse.push(dispatch(entry::COARSE, samples));
    steps.push(pass(layout, "mrsl coarse", Stage::Coarse, KernelRef::new(KernelKind::Coarse, Some(block)), coarse));
    let (fine, fine_entry) = if mode == Mode::Dynamic {
        let inner = KernelRef::new(KernelKind::DynamicCoarse, Some(DYNAMIC_INNER_BLOCK));
        let shade = dispatch(entry::DYNAMIC_COARSE, Workgroups::SampleGrid { block: DYNAMIC_INNER_BLOCK });
        steps.push(pass(layout, "mrsl dynamic coarse 2x2", Stage::Coarse2x2, inner, vec![shade]));
        (KernelKind::DynamicFine, entry::DYNAMIC_FINE)
    } else {
        (KernelKind::Fine, entry::FINE)
    };
    let fine = KernelRef::new(fine, Some(block));
    let dispatches = pixel_dispatches(layout, steps, fine_entry);
    steps.push(pass(layout, "mrsl fine", Stage::Fine, fine, dispatches));
    // The dynamic mode's last counter counts the 2x2 samples it shaded.
    let counter = (mode == Mode::Dynamic).then_some(layout.stats.counters.len());
    Counts {
        samples: SampleCount::Grid { block, counter },
        evaluations: Evaluations::SamplesAndCounted,
        work_lists: None,
        background: None,
    }
}

/// The dispatches of a per-pixel pass that writes the outputs through
/// `entry`: over tile lists where the program has a background rule (after
/// a step clearing their counts), else over every tile.
fn pixel_dispatches(layout: &Layout, steps: &mut Vec<Step>, entry: &str) -> Vec<Dispatch> {
    if layout.has_background() {
        steps.push(Step::Clear { resource: ResourceId::TileCounts });
        tile_list_dispatches(entry)
    } else {
        vec![tiles(entry)]
    }
}

/// A fine pass over tile lists: classify the tiles, turn the lists' lengths
/// into indirect arguments, shade the background tiles with their own entry
/// point and the surface tiles with the full one (`entry`). On llvmpipe no
/// branch spares a lane its work, so the background pixels' savings come
/// only from leaving them out of the full entry point's dispatch.
fn tile_list_dispatches(entry: &str) -> Vec<Dispatch> {
    let listed = |list| Workgroups::Indirect {
        buffer: ResourceId::TileArguments,
        offset: geometry::tile_args_offset(list),
        // The arguments lay the workgroups out in rows as wide as the image's tiles.
        at_most: None,
        per_workgroup: geometry::FINE_WORKGROUP,
    };
    vec![
        tiles(entry::FINE_TILES),
        Dispatch {
            entry: entry::FINE_TILE_ARGS.into(),
            arguments: Some(ResourceId::TileArguments),
            workgroups: Workgroups::One,
        },
        dispatch(entry::FINE_BACKGROUND, listed(geometry::BACKGROUND_TILE_LIST)),
        dispatch(entry, listed(geometry::SURFACE_TILE_LIST)),
    ]
}

/// The multi-rate mode: the 4x4 samples of the `coarse(4)` effects, their
/// values resolved and stored per pixel, the 2x2 samples of the other
/// coarse effects, then the pixels.
fn multi_rate_steps(layout: &Layout, steps: &mut Vec<Step>) -> Counts {
    let (outer, inner) = (DYNAMIC_OUTER_BLOCK, DYNAMIC_INNER_BLOCK);
    let has_outer = has_outer_effects(layout);
    let kernel = |kind, block| KernelRef::new(kind, Some(block));
    // Without `coarse(4)` effects the 4x4 passes dispatch nothing; they stay
    // in the plan, so that a runtime makes their pipelines as for any mode.
    let when = |d: Dispatch| if has_outer { vec![d] } else { vec![] };
    let samples = when(dispatch(entry::COARSE, Workgroups::SampleGrid { block: outer }));
    steps.push(pass(layout, "mrsl multi-rate 4x4", Stage::Coarse, kernel(KernelKind::MultiCoarse, outer), samples));
    let resolve = when(tiles(entry::MULTI_RESOLVE));
    steps.push(pass(layout, "mrsl multi-rate resolve", Stage::Fine, kernel(KernelKind::MultiResolve, outer), resolve));
    let samples = dispatch(entry::COARSE, Workgroups::SampleGrid { block: inner });
    steps.push(pass(
        layout,
        "mrsl multi-rate 2x2",
        Stage::Coarse2x2,
        kernel(KernelKind::MultiCoarse, inner),
        vec![samples],
    ));
    let dispatches = pixel_dispatches(layout, steps, entry::FINE);
    steps.push(pass(layout, "mrsl multi-rate fine", Stage::Fine, kernel(KernelKind::MultiFine, inner), dispatches));
    Counts {
        samples: SampleCount::Levels,
        evaluations: Evaluations::SamplesAndCounted,
        work_lists: None,
        background: None,
    }
}

/// DACS: level 0, then per level classify into the work list, turn its
/// count into indirect arguments and shade the list. With a background rule,
/// first list the tiles: level 0 and the classifications are dispatched over
/// the surface tiles only, and the background tiles have a pass of their own.
fn hierarchical_steps(layout: &Layout, steps: &mut Vec<Step>) -> Counts {
    let kernel = KernelRef::new(KernelKind::Hierarchical, None);
    let tiled = layout.has_background();
    let lattice = |level: u32, l: geometry::Lattice| match tiled {
        false => Workgroups::Lattice { start: l.start, step: l.step, odd_only: l.odd_only },
        true => tile_list(geometry::level_tile_args_offset(level)),
    };
    let mut levels = vec![];
    if tiled {
        let level0 = HIERARCHICAL_LEVEL0;
        let grid = Workgroups::Lattice { start: level0.start, step: level0.step, odd_only: level0.odd_only };
        levels.push(dispatch(entry::HIER_TILES, grid));
        levels.push(Dispatch {
            entry: entry::HIER_TILE_ARGS.into(),
            arguments: Some(ResourceId::LevelArguments),
            workgroups: Workgroups::One,
        });
    }
    // The effects derivatives read elsewhere, at every level-0 pixel first:
    // level 0's predicates take their derivatives from them.
    if crate::layout::hierarchical_level0_values(layout) {
        levels.push(dispatch(entry::HIER_LEVEL0_VALUES, lattice(0, HIERARCHICAL_LEVEL0)));
    }
    levels.push(dispatch(entry::HIER_LEVEL0, lattice(0, HIERARCHICAL_LEVEL0)));
    for (index, level) in HIERARCHICAL_LEVELS.iter().enumerate() {
        let (start, step, odd_only) = (level.start, level.step, level.odd_only);
        levels.push(dispatch(entry::HIER_CLASSIFY[index], lattice(index as u32 + 1, *level)));
        levels.push(Dispatch {
            entry: entry::HIER_ARGS[index].into(),
            arguments: Some(ResourceId::LevelArguments),
            workgroups: Workgroups::One,
        });
        levels.push(dispatch(
            entry::HIER_SHADE[index],
            Workgroups::Indirect {
                buffer: ResourceId::LevelArguments,
                offset: geometry::indirect_args_offset(index as u32 + 1),
                at_most: Some(Extent::Lattice { start, step, odd_only }),
                per_workgroup: WORK_LIST_WORKGROUP,
            },
        ));
    }
    if tiled {
        levels.push(dispatch(entry::HIER_BACKGROUND, tile_list(geometry::background_tile_args_offset())));
    }
    steps.push(Step::Clear { resource: ResourceId::LevelCounts });
    // No final pass: the entry point that completes a pixel's record writes
    // its outputs.
    steps.push(pass(layout, "mrsl hierarchical levels", Stage::Coarse, kernel, levels));
    steps.push(Step::Readback { resource: ResourceId::LevelCounts, bytes: None });
    Counts {
        samples: SampleCount::None,
        evaluations: Evaluations::Counted,
        work_lists: Some(WorkListCounts {
            resource: ResourceId::LevelCounts,
            words_per_level: QUEUE_WORDS_PER_LEVEL,
            levels: (1..=HIERARCHICAL_LEVELS.len() as u32).collect(),
            lanes: WORK_LIST_WORKGROUP,
        }),
        background: None,
    }
}

/// An indirect dispatch over a hierarchical tile list, whose arguments are
/// at byte `offset` of the level arguments.
fn tile_list(offset: u64) -> Workgroups {
    Workgroups::Indirect {
        buffer: ResourceId::LevelArguments,
        offset,
        // The arguments lay the workgroups out in rows of as many tiles as the image has across.
        at_most: None,
        per_workgroup: geometry::COARSE_WORKGROUP * geometry::COARSE_WORKGROUP,
    }
}

/// Software VRS: list the samples each tile's rate needs, shade them from
/// the list (indirect), then resolve every pixel.
fn rate_image_steps(layout: &Layout, steps: &mut Vec<Step>) -> Counts {
    let list = vec![
        dispatch(entry::RATE_LIST, Workgroups::RateTiles),
        Dispatch {
            entry: entry::RATE_ARGS.into(),
            arguments: Some(ResourceId::SampleArguments),
            workgroups: Workgroups::One,
        },
        dispatch(
            entry::RATE_COARSE,
            Workgroups::Indirect {
                buffer: ResourceId::SampleArguments,
                offset: 0,
                // The arguments lay the workgroups out in rows (`RATE_ARGS_MAX_X` wide).
                at_most: None,
                per_workgroup: WORK_LIST_WORKGROUP,
            },
        ),
    ];
    steps.push(Step::Clear { resource: ResourceId::SampleCount });
    let coarse = KernelRef::new(KernelKind::RateCoarse, None);
    steps.push(pass(layout, "mrsl rate-image coarse", Stage::Coarse, coarse, list));
    let fine = KernelRef::new(KernelKind::RateFine, None);
    let dispatches = pixel_dispatches(layout, steps, entry::RATE_FINE);
    steps.push(pass(layout, "mrsl rate-image fine", Stage::Fine, fine, dispatches));
    steps.push(Step::Readback { resource: ResourceId::SampleCount, bytes: Some(4) });
    Counts {
        samples: SampleCount::Listed { resource: ResourceId::SampleCount, word: 0 },
        evaluations: Evaluations::SamplesAndCounted,
        work_lists: None,
        background: None,
    }
}

fn pass(layout: &Layout, label: &str, stage: Stage, kernel: KernelRef, dispatches: Vec<Dispatch>) -> Step {
    let bindings = stage_bindings(layout, kernel);
    // Measured on the kernel once it is written (`mrsl::compile`).
    Step::Pass(Pass { label: label.into(), stage, kernel, bindings, dispatches, workgroup_bytes: 0 })
}

fn dispatch(entry: &str, workgroups: Workgroups) -> Dispatch {
    Dispatch { entry: entry.into(), arguments: None, workgroups }
}

fn tiles(entry: &str) -> Dispatch {
    dispatch(entry, Workgroups::Tiles)
}

/// The resources a kernel of `kernel`'s kind binds for its own work, before
/// those every per-pixel pass adds (tile lists, statistics, outputs).
fn kernel_resources(layout: &Layout, kernel: KernelRef) -> Vec<PassBinding> {
    use BindingType as T;
    use ResourceId as R;
    let h = &layout.hierarchical;
    let at = |binding, resource, ty| PassBinding { binding, resource, ty };
    let buffer = |binding, resource, read_only| at(binding, resource, T::Buffer { read_only });
    let block = kernel.block.unwrap_or(1);
    let interface = layout.interface.binding;
    let shading_rate = at(layout.shading_rate.binding, R::ShadingRate, T::UintTexture);
    match kernel.kind {
        KernelKind::Coarse => {
            let mut coarse = vec![at(interface, R::Records { block }, T::RecordStorageTexture)];
            if layout.neighbours.words > 0 {
                coarse.push(at(layout.neighbours.binding, R::NeighbourValues { block }, T::WordTexture));
            }
            coarse
        }
        KernelKind::Fine => vec![at(interface, R::Records { block }, T::RecordTexture)],
        // Its interface and neighbour values are in workgroup memory.
        KernelKind::Tile => vec![],
        // Reads the 4x4 level, writes the 2x2 level and counts its samples.
        KernelKind::DynamicCoarse => vec![
            at(interface, R::Records { block: DYNAMIC_OUTER_BLOCK }, T::RecordTexture),
            buffer(layout.interface2.binding, R::TaggedRecords { block: DYNAMIC_INNER_BLOCK }, false),
            buffer(layout.stats.binding, R::Statistics, false),
        ],
        KernelKind::DynamicFine => vec![
            at(interface, R::Records { block: DYNAMIC_OUTER_BLOCK }, T::RecordTexture),
            buffer(layout.interface2.binding, R::TaggedRecords { block: DYNAMIC_INNER_BLOCK }, true),
        ],
        KernelKind::Reference => vec![],
        KernelKind::Hierarchical => {
            let mut hierarchical = vec![
                if h.packed {
                    at(h.values_binding, R::PackedPixelRecords, T::PackedWordTexture)
                } else {
                    at(h.values_binding, R::PixelRecords, T::WordTexture)
                },
                buffer(h.work_binding, R::WorkLists, false),
                buffer(h.queue_binding, R::LevelCounts, false),
            ];
            // Level 0's lattice is the 4x4 block modes' sample grid.
            if crate::layout::hierarchical_level0_values(layout) {
                let block = HIERARCHICAL_LEVEL0.step;
                hierarchical.push(at(layout.neighbours.binding, R::NeighbourValues { block }, T::WordTexture));
            }
            hierarchical
        }
        KernelKind::Checkerboard => vec![at(h.values_binding, R::PixelRecords, T::WordTexture)],
        KernelKind::RateCoarse => vec![
            buffer(interface, R::RateRecords, false),
            buffer(h.work_binding, R::SampleList, false),
            buffer(h.queue_binding, R::SampleCount, false),
            shading_rate,
        ],
        KernelKind::RateFine => vec![buffer(interface, R::RateRecords, true), shading_rate],
        KernelKind::MultiCoarse => {
            let mut coarse = vec![at(interface, R::LevelRecords { block }, T::RecordStorageTexture)];
            if block == DYNAMIC_INNER_BLOCK {
                coarse.extend(level_values(layout, false));
            }
            coarse
        }
        KernelKind::MultiResolve => {
            let mut resolve = vec![at(interface, R::LevelRecords { block }, T::RecordTexture)];
            resolve.extend(level_values(layout, true));
            resolve
        }
        KernelKind::MultiFine => {
            let mut fine = vec![at(interface, R::LevelRecords { block }, T::RecordTexture)];
            fine.extend(level_values(layout, true));
            fine
        }
    }
}

/// The stage group (group 2) the kernel declares, in binding order: what
/// the code generator writes and what a runtime binds.
pub fn stage_bindings(layout: &Layout, kernel: KernelRef) -> Vec<PassBinding> {
    use BindingType as T;
    use ResourceId as R;
    let h = &layout.hierarchical;
    let at = |binding, resource, ty| PassBinding { binding, resource, ty };
    let buffer = |binding, resource, read_only| at(binding, resource, T::Buffer { read_only });
    let block = kernel.block.unwrap_or(1);
    let mut bindings = kernel_resources(layout, kernel);
    // With a background rule the per-pixel passes that write the outputs shade over tile lists.
    if kernel.kind.has_tile_lists() && layout.has_background() {
        bindings.push(buffer(h.work_binding, R::TileLists, false));
        bindings.push(buffer(h.queue_binding, R::TileCounts, false));
    }
    // With a background rule the coarse kernels count the background samples.
    // (The multi-rate mode counts its 2x2 samples, those of its finest grid.)
    let counts_background = match kernel.kind {
        KernelKind::Coarse | KernelKind::RateCoarse | KernelKind::Tile => true,
        KernelKind::MultiCoarse => block == DYNAMIC_INNER_BLOCK,
        _ => false,
    } && layout.has_background();
    if counts_background {
        bindings.push(buffer(layout.stats.binding, R::Statistics, false));
    }
    if kernel.kind.writes_outputs() {
        bindings.extend(
            layout
                .outputs
                .iter()
                .enumerate()
                .map(|(index, o)| at(o.binding, R::Output { index }, T::StorageTexture { format: o.format })),
        );
    }
    let counts = kernel.kind.is_fine()
        || matches!(kernel.kind, KernelKind::Tile | KernelKind::Hierarchical | KernelKind::Checkerboard);
    // The multi-rate resolve pass counts the `coarse(4)` effects, where there are any.
    let counts = counts && (kernel.kind != KernelKind::MultiResolve || has_outer_effects(layout));
    if counts && !layout.stats.counters.is_empty() {
        bindings.push(buffer(layout.stats.binding, R::Statistics, false));
        let format = TextureFormat::Rg32Uint;
        bindings.push(at(layout.refine_mask.binding, R::RefineMask, T::StorageTexture { format }));
    }
    bindings.sort_by_key(|b| b.binding);
    // The tile kernel counts background samples and re-evaluations in the same statistics.
    bindings.dedup();
    bindings
}

/// Whether the multi-rate mode has live `coarse(4)` effects to shade at its 4x4 level.
fn has_outer_effects(layout: &Layout) -> bool {
    let Some(levels) = &layout.levels else { return false };
    let block_of = |name: &str| layout.effects.iter().position(|e| e.name == name).map(|k| levels.block[k]);
    layout.stats.counters.iter().any(|name| block_of(name) == Some(DYNAMIC_OUTER_BLOCK))
}

/// The multi-rate mode's stored values, where the kernel reads any: the
/// values (`with_mask` false: the 2x2 level's coarse pass), or the values
/// and the resolve pass's refine-mask word ([`level_values_layers`]).
fn level_values(layout: &Layout, with_mask: bool) -> Option<PassBinding> {
    let values = &layout.levels.as_ref()?.values;
    let ty = BindingType::WordTexture;
    let layers = if with_mask { level_values_layers(layout) } else { values.words };
    (layers > 0).then_some(PassBinding { binding: values.binding, resource: ResourceId::LevelValues, ty })
}

/// The layers of the multi-rate mode's stored values: a layer per word of
/// the values (layout `levels.values`), then, where the 4x4 level has live
/// coarse effects, the refine-mask word the resolve pass wrote for them at
/// the pixel, which the fine pass's refine mask takes their bits from (the
/// fine pass reads their values as stored; the mask must say where the
/// resolve pass evaluated them).
pub fn level_values_layers(layout: &Layout) -> u32 {
    let words = layout.levels.as_ref().map_or(0, |l| l.values.words);
    words + u32::from(has_outer_effects(layout))
}

/// The descriptor of a runtime-owned resource.
fn resource(layout: &Layout, id: ResourceId) -> ResourceDesc {
    use ResourceId as R;
    let words = |elements, words| Shape::Buffer { elements, words };
    let counters = u64::from(geometry::HIERARCHICAL_LEVEL_COUNT * QUEUE_WORDS_PER_LEVEL);
    let stride = layout.interface.stride_words;
    let (what, shape) = match id {
        R::Records { block } => (
            "the record texture",
            Shape::TextureArray {
                texels: Extent::SampleGrid { block },
                layers: layout.interface.layers(),
                format: TextureFormat::Rgba32Uint,
            },
        ),
        R::NeighbourValues { block } => (
            "the neighbour values",
            Shape::TextureArray {
                texels: Extent::SampleGrid { block },
                layers: layout.neighbours.words,
                format: TextureFormat::R32Uint,
            },
        ),
        R::TaggedRecords { block } => {
            ("the 2x2 level", words(Extent::SampleGrid { block }, stride + geometry::DYNAMIC_TAG_WORDS))
        }
        R::PixelRecords => (
            "the per-pixel record texture",
            Shape::TextureArray {
                texels: Extent::Pixels,
                layers: layout.hierarchical.record_words,
                format: TextureFormat::R32Uint,
            },
        ),
        R::PackedPixelRecords => (
            "the packed per-pixel record texture",
            Shape::TextureArray {
                texels: Extent::Pixels,
                layers: layout.hierarchical.record_words.div_ceil(4),
                format: TextureFormat::Rgba32Uint,
            },
        ),
        R::WorkLists => ("the hierarchical work lists", words(Extent::HierarchicalLevels, 1)),
        R::LevelCounts => ("the hierarchical level counts", words(Extent::Fixed { count: counters }, 1)),
        R::LevelArguments => {
            let count = u64::from(geometry::HIERARCHICAL_ARGUMENT_WORDS);
            ("the hierarchical dispatch arguments", words(Extent::Fixed { count }, 1))
        }
        R::RateRecords => ("the rate-image interface", words(Extent::Pixels, stride.max(1))),
        R::SampleList => ("the rate-image sample list", words(Extent::Pixels, 1)),
        R::SampleCount => ("the rate-image sample count", words(Extent::Fixed { count: rate_words() }, 1)),
        R::SampleArguments => ("the rate-image dispatch arguments", words(Extent::Fixed { count: rate_words() }, 1)),
        R::TileLists => {
            let tiles = Extent::Lattice { start: 0, step: geometry::TILE, odd_only: false };
            ("the fine pass's tile lists", words(tiles, 1))
        }
        R::TileCounts => ("the tile-list counts", words(Extent::Fixed { count: u64::from(geometry::TILE_LISTS) }, 1)),
        R::TileArguments => {
            let count = u64::from(geometry::TILE_LISTS * QUEUE_WORDS_PER_LEVEL);
            ("the tile lists' dispatch arguments", words(Extent::Fixed { count }, 1))
        }
        R::Statistics => ("the statistics counters", words(Extent::Fixed { count: layout.stats_counters() as u64 }, 1)),
        R::RefineMask => ("the refine mask", Shape::Texture { format: TextureFormat::Rg32Uint }),
        R::LevelRecords { block } => {
            let levels = layout.levels.as_ref().expect("the multi-rate mode has levels");
            let level = if block == DYNAMIC_OUTER_BLOCK { &levels.outer } else { &levels.inner };
            let (texels, format) = (Extent::SampleGrid { block }, TextureFormat::Rgba32Uint);
            ("a multi-rate level's records", Shape::TextureArray { texels, layers: level.layers(), format })
        }
        R::LevelValues => {
            let layers = level_values_layers(layout).max(1);
            let (texels, format) = (Extent::Pixels, TextureFormat::R32Uint);
            ("the multi-rate mode's stored values", Shape::TextureArray { texels, layers, format })
        }
        R::ShadingRate | R::Output { .. } => unreachable!("engine-bound resources have no descriptor"),
    };
    ResourceDesc { id, what: what.into(), shape, readable: id == R::RefineMask }
}

/// Words of the rate-image mode's counter and of its indirect arguments.
fn rate_words() -> u64 {
    geometry::RATE_QUEUE_BYTES / 4
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pass of a kernel binds the same stage group, so a runtime can
    /// make one bind group layout per kernel.
    #[test]
    fn a_kernel_binds_the_same_group_in_every_pass() {
        let source = "in float3 normal;\ncoarse effect float d = normal.y;\nfine out float4 color = float4(d);\n";
        let program = crate::compile(source, &crate::Options::default()).unwrap();
        let plan = &program.layout.plan;
        // Every mode has a plan, and the block modes one per kind of device.
        for mode in Mode::ALL {
            let plans: Vec<Option<Device>> = plan.modes.iter().filter(|m| m.mode == mode).map(|m| m.device).collect();
            assert_eq!(plans, devices(mode), "{mode}");
        }
        for mode in &plan.modes {
            for pass in mode.passes() {
                assert_eq!(pass.bindings, stage_bindings(&program.layout, pass.kernel), "{}", pass.label);
                assert!(mode.kernels.contains(&pass.kernel), "{}: {}", mode.mode, pass.kernel);
            }
        }
        for id in plan.modes.iter().flat_map(|m| m.resources()) {
            assert_eq!(plan.resource(id).is_none(), id.engine_bound(), "{id:?}");
        }
    }

    /// The hierarchical kernel stores level 0's neighbour values where its
    /// stage group has room for them within WebGPU's default of 4 storage
    /// textures (the records, the refine mask, one output and the neighbour
    /// values), and keeps the quad pair at level 0 beyond it: a second
    /// output must not cost a default device the mode.
    #[test]
    fn level0_values_only_within_the_default_storage_textures() {
        let effects = "in float3 normal;\ncoarse effect float d = normal.y;\n\
                       coarse effect float e {\n    e = d * 2.0;\n    if (fwidth(d) > 0.1) refine;\n}\n\
                       fine out float4 color = float4(e);\n";
        let two = format!("{effects}fine out float4 extra = float4(d);\n");
        for (source, stored) in [(effects.to_string(), true), (two, false)] {
            let program = crate::compile(&source, &crate::Options::default()).unwrap();
            let plan = program.layout.plan.mode(Mode::Hierarchical).unwrap();
            let pass = plan.passes().next().unwrap();
            let dispatched = pass.dispatches.iter().any(|d| d.entry == entry::HIER_LEVEL0_VALUES);
            let bound = pass.bindings.iter().any(|b| matches!(b.resource, ResourceId::NeighbourValues { .. }));
            assert_eq!((dispatched, bound), (stored, stored), "{} outputs", program.layout.outputs.len());
            let storage = pass.bindings.iter().filter(|b| b.ty.is_storage_texture()).count();
            assert!(storage <= 4, "{storage} storage textures");
            let kernel = program.kernel(KernelKind::Hierarchical, 0).unwrap();
            assert_eq!(kernel.wgsl.contains("var mrsl_neighbours"), stored);
        }
    }

    /// With a background rule the block (on CPU devices) and dynamic fine
    /// passes classify the tiles and shade the two lists indirectly; without
    /// one they shade every tile directly.
    #[test]
    fn fine_passes_shade_tile_lists_only_with_a_background_rule() {
        let body = "coarse effect float d = normal.y;\nfine out float4 color = float4(d);\n";
        let fine_entries = |source: &str, mode: Mode| {
            let program = crate::compile(source, &crate::Options::default()).unwrap();
            let plan = program.layout.plan.mode_on(mode, Device::Cpu).unwrap().clone();
            let fine = plan.passes().find(|p| p.stage == Stage::Fine).unwrap().clone();
            let cleared = plan.steps.contains(&Step::Clear { resource: ResourceId::TileCounts });
            (fine.dispatches.iter().map(|d| d.entry.clone()).collect::<Vec<_>>(), cleared)
        };
        let with = format!("in float3 normal;\n@background(255) in uint material;\n{body}");
        for (mode, main) in
            [(Mode::Coarse4x4, entry::FINE), (Mode::Coarse2x2, entry::FINE), (Mode::Dynamic, entry::DYNAMIC_FINE)]
        {
            let listed = [entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, main];
            assert_eq!(fine_entries(&with, mode), (listed.iter().map(|e| e.to_string()).collect(), true), "{mode}");
            assert_eq!(fine_entries(&format!("in float3 normal;\n{body}"), mode), (vec![main.to_string()], false));
        }
    }

    /// On a GPU the block modes are one dispatch of the tile kernel, which
    /// binds no interface (it is in workgroup memory) and declares the
    /// workgroup memory the plan reports; with a background rule too.
    #[test]
    fn block_modes_are_one_tile_dispatch_on_a_gpu() {
        let body = "coarse effect float d = normal.y;\nfine out float4 color = float4(d);\n";
        for source in [
            format!("in float3 normal;\n{body}"),
            format!("in float3 normal;\n@background(255) in uint material;\n{body}"),
        ] {
            let program = crate::compile(&source, &crate::Options::default()).unwrap();
            for mode in [Mode::Coarse2x2, Mode::Coarse4x4] {
                let block = mode.block_size().unwrap();
                let plan = program.layout.plan.mode_on(mode, Device::Gpu).unwrap();
                let passes: Vec<&Pass> = plan.passes().collect();
                assert_eq!(passes.len(), 1, "{mode}");
                assert_eq!(passes[0].kernel, KernelRef::new(KernelKind::Tile, Some(block)));
                let side = program.layout.tile.side(block);
                assert_eq!(passes[0].dispatches, vec![dispatch(entry::TILE, Workgroups::PixelTiles { side })]);
                let clears = plan.steps.iter().filter(|s| matches!(s, Step::Clear { .. })).count();
                assert_eq!(clears, 1, "only the statistics are cleared");
                assert!(passes[0].bindings.iter().all(|b| !matches!(b.resource, ResourceId::Records { .. })));
                let bytes = passes[0].workgroup_bytes;
                assert!(bytes > 0 && bytes <= geometry::TILE_WORKGROUP_BYTES, "{bytes}");
                let estimate = crate::layout::tile_workgroup_bytes(&program.layout, program.layout.tile);
                assert!(bytes <= estimate, "the layout's estimate {estimate} bounds the kernel's {bytes} bytes");
            }
        }
    }
}

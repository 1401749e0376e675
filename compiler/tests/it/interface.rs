//! The coarse-to-fine interface on cases whose optimum is known by hand.

use crate::compile_ok;
use mrsl::Layout;

/// Slots as sorted lists of effect names, and the record's total value words.
fn slots(layout: &Layout) -> (Vec<Vec<String>>, u32) {
    let mut slots: Vec<Vec<String>> = layout.interface.slots.iter().map(|s| s.effects.clone()).collect();
    slots.sort();
    let words = layout.interface.slots.iter().map(|s| s.size).sum();
    (slots, words)
}

fn names(list: &[&[&str]]) -> Vec<Vec<String>> {
    let mut v: Vec<Vec<String>> = list.iter().map(|s| s.iter().map(|n| n.to_string()).collect()).collect();
    v.sort();
    v
}

const HEADER: &str = "in float3 normal;\nin float2 uv;\nuniform float t = 0.1;\n";

#[test]
fn single_effect_is_passed_in_its_own_slot() {
    let p = compile_ok(&format!(
        "{HEADER}coarse effect float d {{ d = saturate(normal.y); if (fwidth(d) > t) refine; }}\nfine out float4 color = float4(d);"
    ));
    assert_eq!(slots(&p.layout), (names(&[&["d"]]), 1));
    assert_eq!(p.layout.interface.flag_words, 1);
    assert_eq!(p.layout.interface.stride_words, 2);
    assert!(p.layout.interface.minimal);
}

/// shadow reads blocker; only shadow is read per pixel. blocker is passed only
/// when shadow refines (then shadow is not passed): the two share one slot.
#[test]
fn shadow_and_blocker_share_a_slot() {
    let p = compile_ok(&format!(
        "{HEADER}
coarse effect float blocker {{ blocker = normal.x * 0.5; if (blocker > t) refine; }}
coarse effect float shadow {{ shadow = saturate(blocker + normal.z); if (shadow > 0.02 && shadow < 0.98) refine; }}
fine out float4 color = float4(shadow);"
    ));
    assert_eq!(slots(&p.layout), (names(&[&["blocker", "shadow"]]), 1));
    let blocker = p.layout.effects.iter().find(|e| e.name == "blocker").unwrap();
    assert_eq!(blocker.pass_condition.as_deref(), Some("!r_blocker && r_shadow"));
    let shadow = p.layout.effects.iter().find(|e| e.name == "shadow").unwrap();
    assert_eq!(shadow.pass_condition.as_deref(), Some("!r_shadow && fine"));
}

/// Sizes count: a float3 and a float with exclusive conditions share a 3-word slot.
#[test]
fn shared_slot_is_as_wide_as_its_widest_effect() {
    let p = compile_ok(&format!(
        "{HEADER}
coarse effect float blocker = normal.x;
coarse effect float3 shadow {{ shadow = float3(blocker) * normal; if (shadow.x > t) refine; }}
fine out float4 color = float4(shadow, 1.0);"
    ));
    assert_eq!(slots(&p.layout), (names(&[&["blocker", "shadow"]]), 3));
}

/// a -> b -> c -> out, all refinable: a and b exclude each other, b and c
/// too, a and c interfere: the optimum is two slots.
#[test]
fn chain_of_three_needs_two_slots() {
    let p = compile_ok(&format!(
        "{HEADER}
coarse effect float a {{ a = normal.x; if (a > t) refine; }}
coarse effect float b {{ b = a * 2.0; if (b > t) refine; }}
coarse effect float c {{ c = b + 1.0; if (c > t) refine; }}
fine out float4 color = float4(c);"
    ));
    let (s, words) = slots(&p.layout);
    assert_eq!(words, 2);
    assert_eq!(s.len(), 2);
    // a and c interfere, so they never share.
    assert!(!s.iter().any(|slot| slot.contains(&"a".to_string()) && slot.contains(&"c".to_string())));
}

/// A chain of six refinable effects: the interference graph is the complement
/// of a path, whose chromatic number is ceil(6 / 2) = 3.
#[test]
fn chain_of_six_needs_three_slots() {
    let mut src = HEADER.to_string();
    src.push_str("coarse effect float e0 { e0 = normal.x; if (e0 > t) refine; }\n");
    for k in 1..6 {
        src.push_str(&format!("coarse effect float e{k} {{ e{k} = e{} * 0.5; if (e{k} > t) refine; }}\n", k - 1));
    }
    src.push_str("fine out float4 color = float4(e5);");
    let p = compile_ok(&src);
    assert_eq!(slots(&p.layout).1, 3);
    assert!(p.layout.interface.minimal);
}

/// a -> {b, c} -> d -> out, all refinable. a, b and c are pairwise
/// interfering (a 3-clique); d excludes b and c. Optimum: 3 slots, d shares.
#[test]
fn diamond_needs_three_slots() {
    let p = compile_ok(&format!(
        "{HEADER}
coarse effect float a {{ a = normal.x; if (a > t) refine; }}
coarse effect float b {{ b = a * 2.0; if (b > t) refine; }}
coarse effect float c {{ c = a + 1.0; if (c > t) refine; }}
coarse effect float d {{ d = b * c; if (d > t) refine; }}
fine out float4 color = float4(d);"
    ));
    let (s, words) = slots(&p.layout);
    assert_eq!(words, 3);
    let with_d = s.iter().find(|slot| slot.contains(&"d".to_string())).unwrap();
    assert_eq!(with_d.len(), 2, "d shares a slot with b or c: {s:?}");
}

/// An effect read only by coarse effects that never refine is never passed.
#[test]
fn effects_read_only_at_coarse_rate_are_never_passed() {
    let p = compile_ok(&format!(
        "{HEADER}
coarse effect float base = normal.x;
coarse effect float lit = base * 2.0;
fine out float4 color = float4(lit);"
    ));
    assert_eq!(slots(&p.layout), (names(&[&["lit"]]), 1));
    assert_eq!(p.layout.interface.flag_words, 0);
    let base = p.layout.effects.iter().find(|e| e.name == "base").unwrap();
    assert_eq!(base.slot, None);
    assert_eq!(base.pass_condition, None);
}

/// Effects read per pixel unconditionally all interfere: one slot each.
#[test]
fn independent_effects_each_get_a_slot() {
    let mut src = HEADER.to_string();
    let n = 40;
    for k in 0..n {
        src.push_str(&format!("coarse effect float e{k} = normal.x * {k}.0;\n"));
    }
    let sum: Vec<String> = (0..n).map(|k| format!("e{k}")).collect();
    src.push_str(&format!("fine out float4 color = float4({});", sum.join(" + ")));
    let p = compile_ok(&src);
    assert_eq!(slots(&p.layout).1, n);
    assert!(!p.layout.interface.minimal, "40 passed effects are beyond the exact search");
}

/// Dozens of effects: 20 shadow/blocker pairs (40 passed effects, beyond the
/// exact search). Pairs share, different pairs interfere: 20 slots of 3 words.
#[test]
fn wide_case_reaches_the_optimum_with_the_heuristic() {
    let mut src = HEADER.to_string();
    let pairs = 20;
    for k in 0..pairs {
        src.push_str(&format!("coarse effect float b{k} = normal.x * {k}.0;\n"));
        src.push_str(&format!("coarse effect float3 s{k} {{ s{k} = normal * b{k}; if (s{k}.x > t) refine; }}\n"));
    }
    let sum: Vec<String> = (0..pairs).map(|k| format!("s{k}")).collect();
    src.push_str(&format!("fine out float4 color = float4({}, 1.0);", sum.join(" + ")));
    let p = compile_ok(&src);
    let (s, words) = slots(&p.layout);
    assert_eq!(s.len(), pairs);
    assert_eq!(words, 3 * pairs as u32);
    for k in 0..pairs {
        assert!(s.contains(&vec![format!("b{k}"), format!("s{k}")]), "pair {k} shares: {s:?}");
    }
}

/// Refine flags pack into bits: 33 refinable effects need two flag words.
#[test]
fn refine_flags_pack_into_words() {
    let mut src = HEADER.to_string();
    let n = 33;
    for k in 0..n {
        src.push_str(&format!("coarse effect float e{k} {{ e{k} = normal.x * {k}.0; if (e{k} > t) refine; }}\n"));
    }
    let sum: Vec<String> = (0..n).map(|k| format!("e{k}")).collect();
    src.push_str(&format!("fine out float4 color = float4({});", sum.join(" + ")));
    let p = compile_ok(&src);
    assert_eq!(p.layout.interface.flag_words, 2);
    let bits: Vec<u32> = p.layout.effects.iter().filter_map(|e| e.refine_bit).collect();
    assert_eq!(bits.len(), n as usize);
    assert_eq!(p.layout.interface.stride_words, 2 + n);
}

/// The exact colouring equals a brute-force optimum over all set partitions,
/// on 300 random graphs of up to 8 passed effects with random widths.
#[test]
fn exact_colouring_matches_brute_force() {
    use mrsl::internals::EffectId;
    let mut seed = 0x2545F4914F6CDD1Du64;
    let mut next = move || {
        // xorshift64: deterministic and dependency-free.
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for _ in 0..300 {
        let n = 1 + (next() % 8) as usize;
        let nodes: Vec<EffectId> = (0..n as u32).map(EffectId).collect();
        let sizes: Vec<u32> = (0..n).map(|_| 1 + (next() % 4) as u32).collect();
        let mut edges = vec![];
        for a in 0..n {
            for b in a + 1..n {
                if next() % 100 < 40 {
                    edges.push((EffectId(a as u32), EffectId(b as u32)));
                }
            }
        }
        let adjacent =
            |a: usize, b: usize| edges.iter().any(|&(x, y)| (x.0 as usize, y.0 as usize) == (a.min(b), a.max(b)));
        let (classes, exact) = mrsl::internals::colour(&nodes, &sizes, &edges);
        assert!(exact);
        let cost = |classes: &[Vec<usize>]| {
            classes.iter().map(|c| c.iter().map(|&k| sizes[k]).max().unwrap_or(0)).sum::<u32>()
        };
        for c in &classes {
            for (i, &a) in c.iter().enumerate() {
                for &b in &c[i + 1..] {
                    assert!(!adjacent(a, b), "interfering {a} and {b} share a slot");
                }
            }
        }
        assert_eq!(classes.iter().map(|c| c.len()).sum::<usize>(), n);
        // Brute force: every set partition, built vertex by vertex.
        fn partitions(v: usize, n: usize, parts: &mut Vec<Vec<usize>>, visit: &mut dyn FnMut(&[Vec<usize>])) {
            if v == n {
                visit(parts);
                return;
            }
            for k in 0..parts.len() {
                parts[k].push(v);
                partitions(v + 1, n, parts, visit);
                parts[k].pop();
            }
            parts.push(vec![v]);
            partitions(v + 1, n, parts, visit);
            parts.pop();
        }
        let mut best = u32::MAX;
        partitions(0, n, &mut vec![], &mut |parts| {
            if parts.iter().all(|p| p.iter().enumerate().all(|(i, &a)| p[i + 1..].iter().all(|&b| !adjacent(a, b)))) {
                best = best.min(cost(parts));
            }
        });
        assert_eq!(cost(&classes), best, "sizes {sizes:?} edges {edges:?}: got {classes:?}");
    }
}

/// The multi-rate mode's two records, each over its own level's effects:
/// `occlusion` is read by a coarse(2) effect and per pixel (always passed),
/// `blocker` only where the coarse(4) `shadow` refines, so they share; the
/// 2x2 record holds only `spec`, the coarse(4) values being stored per pixel.
#[test]
fn each_multi_rate_level_has_its_own_minimal_record() {
    let source = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/ok/0077_coarse4_read_per_pixel_and_at_2x2.mrsl"),
    )
    .unwrap();
    let p = compile_ok(&source);
    let levels = p.layout.levels.as_ref().expect("compiled for the multi-rate mode");
    let sorted = |l: &mrsl_abi::InterfaceLayout| {
        let mut s: Vec<Vec<String>> = l.slots.iter().map(|s| s.effects.clone()).collect();
        s.sort();
        s
    };
    assert_eq!(sorted(&levels.outer), names(&[&["blocker", "shadow"], &["occlusion"]]));
    assert_eq!(sorted(&levels.inner), names(&[&["spec"]]));
    assert_eq!((levels.outer.flag_words, levels.inner.flag_words), (1, 1));
    let stored: Vec<&str> = levels.values.effects.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(stored, ["shadow", "occlusion"], "the coarse(4) effects a finer one reads, in dependency order");
    assert!(levels.outer.minimal && levels.inner.minimal);
}

/// Every boundary of the multi-rate mode is minimal, on every corpus case
/// and example: an independent solver reads the layout alone (dependencies,
/// levels, refine bits, types), decides interference by enumerating every
/// assignment of the level's refine flags, and finds the least total slot
/// width over all partitions of the passed effects into non-interfering
/// sets. The layout's slots must hold exactly the effects that can be
/// passed, never two that interfere, and be that wide.
#[test]
fn multi_rate_boundaries_match_an_independent_solver_on_the_corpus() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<std::path::PathBuf> = ["tests/data/ok", "../examples"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(root.join(dir)).unwrap().map(|e| e.unwrap().path()))
        .filter(|p| p.extension().is_some_and(|e| e == "mrsl"))
        .collect();
    files.sort();
    let options = mrsl::Options::for_modes(&[mrsl::Mode::MultiRate]);
    let (mut checked, mut three_rate) = (0, 0);
    for path in &files {
        let source = std::fs::read_to_string(path).unwrap();
        let p = mrsl::compile(&source, &options).unwrap_or_else(|_| panic!("{} compiles", path.display()));
        let levels = p.layout.levels.as_ref().unwrap();
        three_rate += usize::from(levels.block.contains(&4));
        for (block, record) in [(4, &levels.outer), (2, &levels.inner)] {
            if let Some(optimum) = level_optimum(&p.layout, block, path) {
                let words: u32 = record.slots.iter().map(|s| s.size).sum();
                assert_eq!(words, optimum, "{}: the {block}x{block} record", path.display());
                checked += 1;
            }
        }
    }
    assert!(three_rate >= 3, "the corpus has three-rate programs ({three_rate})");
    assert!(checked >= 2 * files.len() - 4, "solved {checked} records of {} programs", files.len());
}

/// The least total slot width of the `block` level's record, or `None` when
/// the level has too many refine flags or passed effects to enumerate. Also
/// checks that the record's slots are a colouring of exactly those effects.
fn level_optimum(layout: &Layout, block: u32, path: &std::path::Path) -> Option<u32> {
    let levels = layout.levels.as_ref().unwrap();
    let index = |name: &str| layout.effects.iter().position(|e| e.name == name).unwrap();
    let at_level: Vec<usize> = (0..layout.effects.len())
        .filter(|&k| {
            layout.effects[k].live && layout.effects[k].rate == mrsl_abi::Rate::Coarse && levels.block[k] == block
        })
        .collect();
    let refinable: Vec<usize> = at_level.iter().copied().filter(|&k| layout.effects[k].refine_bit.is_some()).collect();
    if refinable.len() > 12 {
        return None;
    }
    // Users of each effect, from the dependencies.
    let mut users = vec![vec![]; layout.effects.len()];
    for (k, e) in layout.effects.iter().enumerate() {
        for d in &e.depends_on {
            users[index(d)].push(k);
        }
    }
    let passed_under = |a: usize, r: &dyn Fn(usize) -> bool| {
        !r(a)
            && users[a].iter().any(|&u| {
                layout.effects[u].live
                    && (levels.block[u] < block
                        || (levels.block[u] == block && layout.effects[u].refine_bit.is_some() && r(u)))
            })
    };
    let mut passed_sets: Vec<Vec<usize>> = vec![];
    for bits in 0u32..1 << refinable.len() {
        let r = |k: usize| refinable.iter().position(|&x| x == k).is_some_and(|j| bits >> j & 1 == 1);
        passed_sets.push(at_level.iter().copied().filter(|&a| passed_under(a, &r)).collect());
    }
    let mut passed: Vec<usize> = passed_sets.iter().flatten().copied().collect();
    passed.sort();
    passed.dedup();
    let record = if block == 4 { &levels.outer } else { &levels.inner };
    let mut in_slots: Vec<usize> = record.slots.iter().flat_map(|s| s.effects.iter().map(|n| index(n))).collect();
    in_slots.sort();
    assert_eq!(
        in_slots,
        passed,
        "{}: the {block}x{block} record holds exactly the effects that can be passed",
        path.display()
    );
    let interfere = |a: usize, b: usize| passed_sets.iter().any(|s| s.contains(&a) && s.contains(&b));
    for slot in &record.slots {
        for (i, a) in slot.effects.iter().enumerate() {
            for b in &slot.effects[i + 1..] {
                assert!(!interfere(index(a), index(b)), "{}: `{a}` and `{b}` interfere but share", path.display());
            }
        }
    }
    if passed.len() > 9 {
        return None;
    }
    let width = |k: usize| layout.effects[k].ty.components();
    let mut best = u32::MAX;
    fn partitions(v: usize, items: &[usize], parts: &mut Vec<Vec<usize>>, visit: &mut dyn FnMut(&[Vec<usize>])) {
        if v == items.len() {
            return visit(parts);
        }
        for k in 0..parts.len() {
            parts[k].push(items[v]);
            partitions(v + 1, items, parts, visit);
            parts[k].pop();
        }
        parts.push(vec![items[v]]);
        partitions(v + 1, items, parts, visit);
        parts.pop();
    }
    partitions(0, &passed, &mut vec![], &mut |parts| {
        let independent =
            parts.iter().all(|p| p.iter().enumerate().all(|(i, &a)| p[i + 1..].iter().all(|&b| !interfere(a, b))));
        if independent {
            best = best.min(parts.iter().map(|p| p.iter().map(|&k| width(k)).max().unwrap_or(0)).sum());
        }
    });
    Some(best)
}

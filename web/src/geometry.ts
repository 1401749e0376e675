// Evaluates the plan's dispatch shapes (`Workgroups`) and resource extents
// (`Extent`) for an image size, with the numbers the plan carries
// (`plan.constants`). The formulas are those documented on the Rust types
// of the same names in `mrsl_abi::plan` and `mrsl_abi::geometry`; the
// tests check them against the Rust runtime's images.

import type { Extent, LatticeDesc, PlanConstants, Workgroups } from './contract.js';

export type Size = readonly [number, number];

/** What a dispatch may depend on besides the plan. */
export interface DispatchContext {
  size: Size;
  /** Refinement is forced (the checkerboard then shades every quad). */
  forced: boolean;
  /** The rate-image mode's tile size. */
  rateTile: number;
}

const divCeil = (n: number, d: number): number => Math.ceil(n / d);

/** Coarse samples along each axis for block size `block`: `(W + B - 2) / B + 1` (integer division). */
export function sampleGrid([w, h]: Size, block: number): [number, number] {
  return [Math.floor((w + block - 2) / block) + 1, Math.floor((h + block - 2) / block) + 1];
}

/** Lattice points along an axis of `n` pixels. */
function latticeCount(l: LatticeDesc, n: number): number {
  return n > l.start ? Math.floor((n - l.start - 1) / l.step) + 1 : 0;
}

function latticePoints(l: LatticeDesc, [w, h]: Size): number {
  return latticeCount(l, w) * latticeCount(l, h);
}

/** The shading-rate image's size: one texel per `tile`-pixel tile. */
export function rateImageSize([w, h]: Size, tile: number): [number, number] {
  return [divCeil(w, tile), divCeil(h, tile)];
}

/** How many elements an extent has for a `size` image. */
export function extentCount(g: PlanConstants, extent: Extent, size: Size): number {
  switch (extent.kind) {
    case 'pixels':
      return size[0] * size[1];
    case 'sample_grid': {
      const [nx, ny] = sampleGrid(size, extent.block);
      return nx * ny;
    }
    case 'hierarchical_levels':
      return g.hierarchical_levels.reduce((sum, l) => sum + latticePoints(l, size), 0);
    case 'lattice': {
      const points = latticePoints(extent, size);
      return extent.odd_only ? Math.floor(points / 2) : points;
    }
    case 'fixed':
      return extent.count;
  }
}

/** The 2D grid of an extent that is one (pixels, sample grid). */
export function extentGrid(extent: Extent, size: Size): [number, number] | null {
  switch (extent.kind) {
    case 'pixels':
      return [size[0], size[1]];
    case 'sample_grid':
      return sampleGrid(size, extent.block);
    default:
      return null;
  }
}

/** The workgroups of a direct dispatch; `null` for an indirect one. */
export function directWorkgroups(g: PlanConstants, w: Workgroups, c: DispatchContext): [number, number] | null {
  const [width, height] = c.size;
  switch (w.kind) {
    case 'tiles':
      return [divCeil(width, g.tile), divCeil(height, g.tile)];
    case 'pixel_tiles':
      return [divCeil(width, w.side), divCeil(height, w.side)];
    case 'sample_grid': {
      const [nx, ny] = sampleGrid(c.size, w.block);
      return [divCeil(nx, g.coarse_workgroup), divCeil(ny, g.coarse_workgroup)];
    }
    case 'lattice': {
      const l = { start: w.start, step: w.step, odd_only: w.odd_only ?? false };
      const x = latticeCount(l, width);
      const invocations = [l.odd_only ? divCeil(x, 2) : x, latticeCount(l, height)];
      const groups = (n: number) => Math.max(divCeil(n, g.coarse_workgroup), 1);
      return [groups(invocations[0]!), groups(invocations[1]!)];
    }
    case 'one':
      return [1, 1];
    case 'rate_tiles': {
      const [tx, ty] = rateImageSize(c.size, c.rateTile);
      return [divCeil(tx, g.rate_list_tiles), divCeil(ty, g.rate_list_tiles)];
    }
    case 'checkerboard_quads': {
      const [quadsX, quadsY] = [divCeil(width, 2), divCeil(height, 2)];
      const shadedPerRow = c.forced ? quadsX : divCeil(quadsX, 2);
      return [Math.max(divCeil(shadedPerRow, g.checkerboard_quads_per_workgroup), 1), quadsY];
    }
    case 'indirect':
      return null;
  }
}

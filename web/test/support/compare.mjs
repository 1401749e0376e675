// Comparing the web runtime's image with the Rust runtime's. Both run the
// same WGSL on the same driver (SwiftShader), but Dawn translates it with
// Tint and wgpu with naga: two different SPIR-V modules, in which the
// driver may contract `a * b + c` into one fused multiply-add in one and
// not the other, or order a sum differently. Each such difference moves a
// float result of order 1 (a normalised vector, a colour) by an ulp or
// two, 1.2e-7 each, and a later subtraction carries that absolute error
// into smaller results. Measured over every example and mode at 61x37:
// 7 of 10 examples bit-identical in every mode; demo, derivatives and
// three_rates differ in 21 to 668 of their 9,028 values, by at most 2.4e-7
// (2 ulps of 1).
// The tolerance is 4 ulps of the larger of 1 and the value, twice that;
// a difference in where a pixel refines, or in an integer or 8-bit
// output, is far larger.

/** The most a 32-bit float value may differ, in ulps of max(1, |value|). */
export const MAX_ULPS = 4;

export const TOLERANCE = { describe: `at most ${MAX_ULPS} ulps of max(1, |value|) per 32-bit float value, bit-identical otherwise` };

/** A 32-bit float's ulp at 1. */
const ULP_OF_ONE = 2 ** -23;

/** `{ withinTolerance, summary }` for two tightly packed images of `format`. */
export function compareImages(web, rust, format) {
  if (web.length !== rust.length) {
    return { withinTolerance: false, summary: `sizes differ: ${web.length} bytes against ${rust.length}` };
  }
  let differingBytes = 0;
  for (let i = 0; i < web.length; i++) if (web[i] !== rust[i]) differingBytes++;
  if (differingBytes === 0) return { withinTolerance: true, summary: 'bit-identical', ulps: 0 };
  if (!format.endsWith('32float')) {
    return { withinTolerance: false, summary: `${differingBytes} bytes differ in a ${format} output` };
  }
  const a = new Float32Array(web.buffer, web.byteOffset, web.length / 4);
  const b = new Float32Array(rust.buffer, rust.byteOffset, rust.length / 4);
  let ulps = 0;
  let maxAbs = 0;
  let differing = 0;
  for (let i = 0; i < a.length; i++) {
    if (Object.is(a[i], b[i]) || (Number.isNaN(a[i]) && Number.isNaN(b[i]))) continue;
    differing++;
    const scale = Math.max(1, Math.abs(a[i]), Math.abs(b[i])) * ULP_OF_ONE;
    ulps = Math.max(ulps, Math.abs(a[i] - b[i]) / scale);
    maxAbs = Math.max(maxAbs, Math.abs(a[i] - b[i]));
  }
  const summary = `${differing} of ${a.length} values differ, by at most ${maxAbs.toExponential(2)} (${ulps.toFixed(1)} ulps of max(1, |value|))`;
  return { withinTolerance: ulps <= MAX_ULPS, summary, ulps };
}

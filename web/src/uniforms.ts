// The user uniform block and the control block: values set by name, checked
// against the layout (the name, the count, each value against its scalar
// type), and written at the offsets the layout gives, as WGSL's uniform
// address space lays them out. The checks and messages are the Rust
// runtime's (`mrsl_runtime::Shader::set_uniform`).

import type { Field, UniformBlock } from './contract.js';
import { MrslError } from './errors.js';

type Scalar = 'float' | 'int' | 'uint' | 'bool';

/** An mrsl value type name ("float3", "float4x4", "uint4[2]") as what the writer needs. */
interface ValueType {
  scalar: Scalar;
  components: number;
  /** The side of a square matrix, else 0. */
  matrix: number;
}

function parseType(text: string): ValueType {
  const array = /^(.*)\[(\d+)\]$/.exec(text);
  if (array) {
    const element = parseType(array[1]!);
    return { scalar: element.scalar, components: element.components * Number(array[2]), matrix: 0 };
  }
  const matrix = /^float([234])x\1$/.exec(text);
  if (matrix) {
    const n = Number(matrix[1]);
    return { scalar: 'float', components: n * n, matrix: n };
  }
  const vector = /^(float|int|uint|bool)([234])?$/.exec(text);
  if (!vector) throw new MrslError('program', `\`${text}\` is not an mrsl value type`);
  return { scalar: vector[1] as Scalar, components: vector[2] ? Number(vector[2]) : 1, matrix: 0 };
}

/** Why `value` is not one `scalar` holds exactly, or `null` when it is. */
function badValue(scalar: Scalar, value: number): string | null {
  const integral = Number.isFinite(value) && Number.isInteger(value);
  switch (scalar) {
    case 'float':
      if (!Number.isFinite(value)) return 'is not a finite number';
      if (Math.abs(value) > 3.4028234663852886e38) return 'is beyond the range of a 32-bit float';
      return null;
    case 'int':
      if (!integral) return 'is not an integer';
      if (value < -2147483648 || value > 2147483647) {
        return 'is outside the range of an `int` (i32, -2147483648 to 2147483647)';
      }
      return null;
    case 'uint':
      if (!integral) return 'is not an integer';
      if (value < 0 || value > 4294967295) return 'is outside the range of a `uint` (u32, 0 to 4294967295)';
      return null;
    case 'bool':
      return value === 0 || value === 1 ? null : 'is not 0 or 1 (a bool is set as 0 for false, 1 for true)';
  }
}

/** Writes a field's components at `offset`: matrix columns 16 bytes apart but for `float2x2`. */
function writeField(view: DataView, field: Field, values: readonly number[]): void {
  const ty = parseType(field.type);
  const put = (word: number, v: number) => {
    const at = field.offset + 4 * word;
    if (ty.scalar === 'float') view.setFloat32(at, v, true);
    else if (ty.scalar === 'int') view.setInt32(at, v, true);
    else view.setUint32(at, v, true);
  };
  if (ty.matrix > 0) {
    const n = ty.matrix;
    const columnWords = n === 2 ? 2 : 4;
    for (let col = 0; col < n; col++) {
      for (let row = 0; row < n; row++) put(col * columnWords + row, values[col * n + row]!);
    }
  } else {
    values.forEach((v, i) => put(i, v));
  }
}

/** Uniform values set by name, over a block of the layout. */
export class UniformValues {
  readonly #values = new Map<string, number[]>();

  constructor(private readonly block: UniformBlock | null) {}

  /** The field `name`, or an `unknown-uniform` error. */
  field(name: string): Field {
    const field = this.block?.fields.find((f) => f.name === name);
    if (!field) throw new MrslError('unknown-uniform', `the program has no uniform \`${name}\``, name);
    return field;
  }

  /** Sets `name` after checking the count and every value against its scalar type. */
  set(name: string, values: readonly number[]): void {
    const field = this.field(name);
    const ty = parseType(field.type);
    if (values.length !== ty.components) {
      throw new MrslError(
        'uniform-components',
        `uniform \`${name}\` is \`${field.type}\` (${ty.components} components), but ${values.length} values were given`,
        name,
      );
    }
    values.forEach((value, index) => {
      const reason = badValue(ty.scalar, value);
      if (reason) {
        const at = ty.components === 1 ? `its value ${value}` : `component ${index}, ${value},`;
        throw new MrslError('uniform-value', `uniform \`${name}\` is \`${field.type}\`, but ${at} ${reason}`, name);
      }
    });
    this.#values.set(name, [...values]);
  }

  /** The value set for `name`, or its default, or `null`. */
  get(name: string): number[] | null {
    return this.#values.get(name) ?? this.field(name).default;
  }

  /** The block's bytes, from set values and defaults. */
  bytes(): ArrayBuffer {
    const block = this.block;
    const bytes = new ArrayBuffer(block?.size ?? 0);
    const view = new DataView(bytes);
    for (const field of block?.fields ?? []) {
      const values = this.#values.get(field.name) ?? field.default;
      if (!values) {
        throw new MrslError('missing-uniform', `uniform \`${field.name}\` has no default and was not set`, field.name);
      }
      writeField(view, field, values);
    }
    return bytes;
  }
}

/** The control block's bytes from its fields' values by name (`size`, `force_refine`, ...). */
export function controlBytes(fields: readonly Field[], size: number, values: Record<string, number[]>): ArrayBuffer {
  const bytes = new ArrayBuffer(size);
  const view = new DataView(bytes);
  for (const field of fields) {
    const value = values[field.name] ?? field.default;
    if (!value) throw new MrslError('program', `the control block's field \`${field.name}\` has no value`);
    writeField(view, field, value);
  }
  return bytes;
}

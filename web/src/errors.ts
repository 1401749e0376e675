// The runtime's typed errors: every mismatch between a program's layout and
// what the page binds, checked before anything is recorded, and what the
// device refused. The kinds and messages follow the Rust runtime's
// `mrsl_runtime::Error`.

/** What went wrong; `MrslError.kind` tells them apart. */
export type ErrorKind =
  | 'missing-channel'
  | 'channel-format'
  | 'channel-usage'
  | 'texture-shape'
  | 'size-mismatch'
  | 'missing-uniform'
  | 'unknown-uniform'
  | 'uniform-components'
  | 'uniform-value'
  | 'missing-texture'
  | 'texture-usage'
  | 'missing-sampler'
  | 'missing-output'
  | 'output-format'
  | 'output-usage'
  | 'bad-size'
  | 'unsupported-mode'
  | 'unknown-mode'
  | 'missing-shading-rate'
  | 'rate-format'
  | 'rate-usage'
  | 'rate-image-size'
  | 'bad-tile-size'
  | 'bad-option'
  | 'not-a-texture'
  | 'foreign-device'
  | 'pipeline'
  | 'readback'
  | 'statistics-off'
  | 'program'
  | 'program-file';

/** An error of the mrsl web runtime, naming the binding or option at fault. */
export class MrslError extends Error {
  override readonly name = 'MrslError';

  constructor(
    readonly kind: ErrorKind,
    message: string,
    /** The binding, uniform or mode at fault, where there is one. */
    readonly subject?: string,
  ) {
    super(message);
  }
}

// Per coarse effect, `mrsl_classify`'s test of pixel `p`: sets the effect's bit in its
// mask word where p is shaded, and otherwise stores the mean of the neighbours it
// interpolates. A function per effect, not a block of `mrsl_classify` per effect, so
// that no function grows with the number of effects: naga's front end takes time
// quadratic in the number of expressions of a function.

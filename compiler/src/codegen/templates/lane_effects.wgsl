// Per coarse effect, its part of a lane's work: its value at each of the lane's pixels,
// resampled, or re-evaluated at the pixels that refine it. A function per effect, not a
// block of the lane's function per effect, so that no function grows with the number of
// effects: naga's front end takes time quadratic in the number of expressions of a function.

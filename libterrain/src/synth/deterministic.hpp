#pragma once
// Private: included first by every file of synth/. Determinism: the surface is built from
// IEEE-exact arithmetic and sqrt (no fused multiply-adds, single-threaded, fixed evaluation
// order) and our own PRNG. libm (sin, cos, asin, exp, pow) only sets up the geometry and the
// crater sizes; the last-ulp differences between libms vanish under the 2 m DN quantisation.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

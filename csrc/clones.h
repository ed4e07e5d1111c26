/*
 * clones.h - build-internal: kernels compiled for several x86-64 levels.
 *
 * A function marked MT_CLONES is compiled for the baseline and for newer
 * levels (cpu.h: x86-64-v3 and v4), and the loader picks the best the CPU has:
 * portable wheels without -march=native, at the speed of a native build.
 * Helpers it calls must be MT_INLINE to be compiled for the same level.
 */
#ifndef MT_CLONES_H
#define MT_CLONES_H

#include "cpu.h"

/* The loader's choice is an ifunc, which ELF has. */
#if MT_X86 && defined(__ELF__) && !defined(MT_NO_CLONES)
#define MT_CLONES __attribute__((target_clones("arch=" MT_X86_V4, "arch=" MT_X86_V3, "default")))
#else
#define MT_CLONES
#endif

/* Forced only where clones need it: without them (MT_NO_CLONES, e.g. the sanitizer build) the
 * compiler chooses, which keeps the instrumented build of the big solvers to seconds. */
#if defined(__GNUC__) && !defined(MT_NO_CLONES)
#define MT_INLINE inline __attribute__((always_inline))
#else
#define MT_INLINE inline
#endif

#endif /* MT_CLONES_H */

/*
 * cpu.h - build-internal: the x86-64 levels that code is compiled for beside the baseline, and
 * whether this processor runs them.  One name per level serves the compiler (a function's
 * target, clones.h's target_clones) and the run-time test alike, so that what a function may
 * use and what is checked before it runs cannot drift apart.
 *
 *   x86-64-v3  AVX2, BMI1, BMI2, FMA, LZCNT, MOVBE, F16C (Haswell, Zen 1 on)
 *   x86-64-v4  v3 and AVX-512 F, BW, CD, DQ, VL (Skylake-X, Zen 4 on)
 *
 * MT_X86 is 1 where the compiler takes these names in both places (GCC 12 on; other
 * compilers build the portable code alone).
 */
#ifndef MT_CPU_H
#define MT_CPU_H

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#define MT_X86 1
#define MT_X86_V3 "x86-64-v3"
#define MT_X86_V4 "x86-64-v4"

/* A function compiled for the level; call it only where mt_cpu_runs_v3() / _v4() says so. */
#define MT_V3_CODE __attribute__((target("arch=" MT_X86_V3)))
#define MT_V4_CODE __attribute__((target("arch=" MT_X86_V4)))

/* Whether this processor (and its operating system, which must save the wider registers) runs
   the level's code. */
static inline int mt_cpu_runs_v3(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports(MT_X86_V3) != 0;
}

static inline int mt_cpu_runs_v4(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports(MT_X86_V4) != 0;
}
#else
#define MT_X86 0

static inline int mt_cpu_runs_v3(void)
{
    return 0;
}

static inline int mt_cpu_runs_v4(void)
{
    return 0;
}
#endif

#endif /* MT_CPU_H */

/*
 * gcc_coverage.c - coverage of GCC-instrumented C for libFuzzer (atheris), fuzzing builds only.
 *
 * Clang's -fsanitize=fuzzer-no-link gives libFuzzer 8-bit counters per edge.  GCC has only
 * -fsanitize-coverage=trace-pc, a call to __sanitizer_cov_trace_pc at every basic block, which
 * atheris's libFuzzer takes for a no-op.  This shim, which the instrumented module is linked to,
 * counts each basic block in an 8-bit counter indexed by a hash of its address; the harness
 * (fuzz_scanners.py) registers the counters with libFuzzer once atheris has loaded it, as atheris
 * registers its own for Python code.  (GCC's trace-cmp hooks would bind to libasan's weak no-ops
 * of the same names, which come first: comparisons are not traced.)  Not instrumented itself.
 */
#include <stddef.h>
#include <stdint.h>

enum { SLOTS = 1 << 16 };

static uint8_t counters[SLOTS];
static uintptr_t pcs[2 * SLOTS]; /* libFuzzer's PC table: (pc, flags) per counter */

void __sanitizer_cov_trace_pc(void)
{
    const uintptr_t pc = (uintptr_t)__builtin_return_address(0);
    counters[(pc ^ (pc >> 16)) & (SLOTS - 1)]++;
}

/* Registers the counters through libFuzzer's __sanitizer_cov_8bit_counters_init and _pcs_init. */
void mt_fuzz_connect(void (*counters_init)(uint8_t *, uint8_t *),
                     void (*pcs_init)(const uintptr_t *, const uintptr_t *));
void mt_fuzz_connect(void (*counters_init)(uint8_t *, uint8_t *),
                     void (*pcs_init)(const uintptr_t *, const uintptr_t *))
{
    for (size_t i = 0; i < SLOTS; i++)
        pcs[2 * i] = i + 1;
    counters_init(counters, counters + SLOTS);
    pcs_init(pcs, pcs + 2 * SLOTS);
}

/* The kernels of narrow formats eEmM (csrc/fnarrow.h) for AVX2 (instances.inc), which native.py uses where
 * have_avx2() says the processor runs them (AVX2 and F16C): the same IEEE operations lane by lane, only
 * the instructions differ (no FMA: -ffp-contract=off). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC target("avx2,f16c")
#define KERNELS_NAR
#define ISA avx2
#include "../instances.inc"
#endif

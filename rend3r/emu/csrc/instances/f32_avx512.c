/* The fp32 kernels for AVX-512 (instances.inc), which native.py uses where
 * have_avx512() says the processor runs them (AVX2, F16C and AVX-512 F, VL, BW and DQ): the
 * AVX2 kernels' 256-bit code (but for a float packet's colours, eight doubles: one 512-bit
 * register here, two there), whose compares, selects and conversions the compiler then
 * writes with the AVX-512 mask registers and three-operand logic; the same IEEE operations
 * lane by lane (no FMA: -ffp-contract=off). The nearest-hit pass is f32w_avx512.c's. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC target("avx2,f16c,avx512f,avx512vl,avx512bw,avx512dq")
#define KERNELS_F32
#define NO_NEAREST
#define ISA avx512
#include "../instances.inc"
#endif

/* The fp32 nearest-hit pass for AVX-512 (instances.inc; f32_avx512.c has the other fp32
 * kernels): packets of sixteen rays, one 512-bit register a value. Its lanes compute what
 * eight-lane packets compute (lanes are independent, and a lane's tests and counts never
 * depend on the others'), in half the instructions. The light passes keep eight lanes: a
 * shadow packet's shared bounds decide which tests it counts (docs/emulator.md section 7). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC target("avx2,f16c,avx512f,avx512vl,avx512bw,avx512dq")
#define FLOAT_LANES 16
#define KERNELS_F32
#define NEAREST_ONLY
#define ISA avx512
#include "../instances.inc"
#endif

/* The datapath kernels built for AVX2 (names ending in _avx2); rend3r/emu/native.py uses
 * them when have_avx2() says the processor runs them. The same IEEE operations lane by
 * lane as the baseline build: only the instructions differ (no FMA: -ffp-contract=off). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC target("avx2")

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bounds.h"
#include "colour.h"
#include "cull.h"
#include "fround.h"
#include "grids.h"
#include "kernels.h"
#include "simd.h"

#define ISA avx2
#include "instances.inc"
#undef ISA
#endif

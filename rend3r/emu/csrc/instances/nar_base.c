/* The kernels of narrow formats eEmM (csrc/fnarrow.h) for any processor (instances.inc). */
#define KERNELS_NAR
#define ISA base
#include "../instances.inc"

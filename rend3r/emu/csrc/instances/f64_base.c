/* The fp64 kernels for any processor (instances.inc). */
#define KERNELS_F64
#define ISA base
#include "../instances.inc"

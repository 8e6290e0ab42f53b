/* The fp32 kernels for any processor (instances.inc). */
#define KERNELS_F32
#define ISA base
#include "../instances.inc"

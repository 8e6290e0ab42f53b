/* The fp16 (IEEE subnormals) kernels for any processor (instances.inc). */
#define KERNELS_H16I
#define ISA base
#include "../instances.inc"

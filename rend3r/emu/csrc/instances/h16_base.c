/* The fp16 (subnormals flushed) kernels for any processor (instances.inc). */
#define KERNELS_H16
#define ISA base
#include "../instances.inc"

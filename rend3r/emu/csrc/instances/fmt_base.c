/* The kernels of any format eEmM (csrc/fformat.h) for any processor (instances.inc). */
#define KERNELS_FMT
#define ISA base
#include "../instances.inc"

// The one definition of the dense kernels the element tables are built with (see
// core/detail/table_kernels.hpp).

#define MESHMOTION_DEFINE_TABLE_KERNELS
#include "meshmotion/core/detail/table_kernels.hpp"

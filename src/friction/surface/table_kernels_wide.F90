!> The surface table's kernels (table_kernels.F90) under another module
!> name, compiled for processors with AVX2 (CMakeLists.txt); the table uses
!> them only where the processor has it.
#define TABLE_KERNELS friction_surface_table_kernels_wide
#include "table_kernels.F90"

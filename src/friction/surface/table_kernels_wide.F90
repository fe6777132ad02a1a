!> The surface table's kernels (table_kernels.inc, as in table_kernels.F90)
!> under another module name, compiled for processors with AVX2
!> (CMakeLists.txt); the table uses them only where the processor has it.
module friction_surface_table_kernels_wide
#include "table_kernels.inc"
end module friction_surface_table_kernels_wide

!> The kernels of the surface table (friction_surface_lattice_table,
!> friction_surface_lennard_jones and friction_surface_tricubic): the
!> lattice sum's value and derivatives at the nodes of one column of
!> heights (the table's build), the pair terms of a list of differences,
!> and a cell's polynomial (its evaluation).  A module of its own so that
!> it can be compiled for vectorization (CMakeLists.txt) without touching
!> the direct sum's code.
!>
!> Compiled twice: as friction_surface_table_kernels for every x86-64
!> processor, and through table_kernels_wide.F90 as
!> friction_surface_table_kernels_wide for those with AVX2 (x86-64-v3),
!> which the table chooses at run time when the processor of every process
!> building it has it (lattice_table.f90, `all_can_go_wide`).  The wide copy fuses
!> multiplies and adds, which shortens the cell's polynomial's chain of
!> dependent operations (the evaluation's cost), so the two copies agree to
!> rounding, not bit for bit (tests `table`); nothing here reorders a sum.
module friction_surface_table_kernels
#include "table_kernels.inc"
end module friction_surface_table_kernels

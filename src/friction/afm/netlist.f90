!> One microscope scan line (line 0, trace) as a SPICE netlist for ngspice
!> (docs: netlist); the conventions shared by every scene's netlist are in
!> netlist/spice.f90.  The surface's potential writes its own part
!> (surface_potential's spice): NaF (Eq. 1), HOPG (Eq. 2) and the row have
!> one; a Lennard-Jones lattice sum (Eq. 3) has none and is refused.
module friction_afm_netlist
   use friction_kinds, only: wp, pi, ev_per_angstrom_to_nn, kg_to_internal, n_per_m_to_internal, &
      & ns_per_m_to_internal
   use friction_error, only: error_type, fatal_error, error_input
   use friction_netlist_spice, only: nl, tolerances, control_end, num
   use friction_surface_potential, only: surface_potential, spice_form
   use friction_afm_config, only: afm_config, new_potential
   use friction_afm_trip, only: line_offset
   implicit none
   private

   public :: afm_netlist

contains

   !> Line 0 of the map, trace: Eq. 4 in 2D with the tip's absolute position
   !> as state (as the paper: x_t from the integrated current, x_M = v t).
   !> Internal units (friction_kinds): Å, eV, s; forces out in nN.
   subroutine afm_netlist(c, data_file, version, text, error)
      type(afm_config), intent(in) :: c
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: surface
      type(afm_config) :: direct
      class(surface_potential), allocatable :: potential
      type(spice_form) :: form
      real(wp) :: along(3), start(3), sample_time, trip_time
      integer :: k

      ! (The form only: a lattice sum is built direct, without its table.)
      direct = c
      direct%evaluation = 'direct'
      call new_potential(direct, potential, error)
      if (allocated(error)) return
      call potential%spice(form)
      if (len(form%why) > 0) then
         call fatal_error(error, "--netlist: &surface potential = '"//trim(c%potential)//"' is not supported: " &
            & //form%why, error_input)
         return
      end if
      surface = ''
      do k = 1, size(form%comment)
         surface = surface//'* '//trim(form%comment(k))//nl
      end do
      do k = 1, size(form%names)
         surface = surface//'.param '//trim(form%names(k))//' = '//num(form%values(k))//nl
      end do
      surface = surface(1:len(surface) - len(nl))

      along = c%scan_direction()
      ! Line 0 starts lead_in before its first sample, as the kernel's trace.
      start = [c%origin_x, c%origin_y, 0.0_wp] + line_offset(c, 0) * c%across_direction() - c%lead_in * along
      sample_time = c%length / real(c%nx - 1, wp) / c%velocity
      trip_time = (c%length + c%lead_in) / c%velocity

      text = '* friction '//version//': network model of a microscope tip over a surface (paper §3, §5.1, Eq. 4)' &
         & //nl//'* Written by friction --netlist.  Run:  ngspice -b THIS_FILE   (writes '//data_file//')'//nl &
         & //'*'//nl &
         & //'* m r_t'''' = k (r_M - r_t) - grad V(r_t) - c r_t'',   r_M = r_M(0) + v_M t   (x and y).'//nl &
         & //'* The first line of the map (line 0), trace: the support starts '//num(c%lead_in) &
         & //' A (lead_in) before the'//nl &
         & //'* line''s first sample, the tip at the support and at rest (paper §3.1, §5.1).'//nl &
         & //'* Each state is the voltage of a 1 F capacitor integrating the current of a behavioural'//nl &
         & //'* source equal to its derivative (the nodal form of the paper''s coil network, Fig. 4).'//nl &
         & //'* Units: angstrom, eV, s (mass eV s^2/A^2, spring eV/A^2, damping eV s/A^2); time in s.'//nl &
         & //'* Nodes: xt, yt tip position (A, lattice frame); vx, vy tip velocity (A/s).'//nl &
         & //'* '//data_file//': columns time tip_x tip_y vx vy f_along d_f_along, one header line;'//nl &
         & //'* f_along = k (r_M - r_t) . scan direction in nN, d_f_along its time derivative (nN/s).'//nl &
         & //'* Sample i of the kernel''s line is at time ('//num(c%lead_in)//' + i length/(nx - 1))/velocity' &
         & //', i = 0 .. nx-1.'//nl &
         & //'* ngspice''s first saved point is after its first step, not at time 0 (the initial state).'//nl &
         & //'*'//nl &
         & //surface//nl &
         & //'* tip (&tip, internal units)'//nl &
         & //'.param mass = '//num(c%mass * kg_to_internal)//nl &
         & //'.param kx = '//num(c%kx * n_per_m_to_internal)//nl &
         & //'.param ky = '//num(c%ky * n_per_m_to_internal)//nl &
         & //'.param cx = '//num(c%cx * ns_per_m_to_internal)//nl &
         & //'.param cy = '//num(c%cy * ns_per_m_to_internal)//nl &
         & //'* support path r_M(t) = (xs, ys) + (vmx, vmy) t (&scan, angle '//num(c%angle)//' degrees)'//nl &
         & //'.param xs = '//num(start(1))//nl &
         & //'.param ys = '//num(start(2))//nl &
         & //'.param vmx = '//num(c%velocity * along(1))//nl &
         & //'.param vmy = '//num(c%velocity * along(2))//nl &
         & //'* initial state: tip at the support, at rest'//nl &
         & //'Cxt xt 0 1 IC='//num(start(1))//nl &
         & //'Cyt yt 0 1 IC='//num(start(2))//nl &
         & //'Cvx vx 0 1 IC=0'//nl &
         & //'Cvy vy 0 1 IC=0'//nl &
         & //'* x_t'' = v_x (F1x of Fig. 4b), y_t'' = v_y'//nl &
         & //'Bxt 0 xt I=V(vx)'//nl &
         & //'Byt 0 yt I=V(vy)'//nl &
         & //'* v_x'' = (k_x (x_M - x_t) - dV/dx - c_x v_x)/m (E2, E1 and the damping of Fig. 4a), same in y'//nl &
         & //'Bvx 0 vx I=(kx*(xs + vmx*time - V(xt)) - '//form%gradient_x//' - cx*V(vx))/mass'//nl &
         & //'Bvy 0 vy I=(ky*(ys + vmy*time - V(yt)) - '//form%gradient_y//' - cy*V(vy))/mass'//nl &
         & //tolerances(c%solver%rtol, c%solver%atol)//nl &
         & //'.tran '//num(sample_time)//' '//num(trip_time)//' 0 '//num(sample_time)//' uic'//nl &
         & //'.control'//nl &
         & //'set wr_singlescale'//nl &
         & //'set wr_vecnames'//nl &
         & //'option numdgt=15'//nl &
         & //'run'//nl &
         & //'let tip_x = v(xt)'//nl &
         & //'let tip_y = v(yt)'//nl &
         & //'let vx = v(vx)'//nl &
         & //'let vy = v(vy)'//nl &
         ! The .control language does not see .param values: numbers inline.
         & //'let f_along = '//num(ev_per_angstrom_to_nn)//'*('//num(c%kx * n_per_m_to_internal * along(1)) &
         & //'*('//num(start(1))//' + '//num(c%velocity * along(1))//'*time - tip_x) + ' &
         & //num(c%ky * n_per_m_to_internal * along(2))//'*('//num(start(2))//' + ' &
         & //num(c%velocity * along(2))//'*time - tip_y))'//nl &
         & //'let d_f_along = '//num(ev_per_angstrom_to_nn)//'*('//num(c%kx * n_per_m_to_internal * along(1)) &
         & //'*('//num(c%velocity * along(1))//' - vx) + '//num(c%ky * n_per_m_to_internal * along(2)) &
         & //'*('//num(c%velocity * along(2))//' - vy))'//nl &
         & //'wrdata '//data_file//' tip_x tip_y vx vy f_along d_f_along'//nl &
         & //control_end()
   end subroutine afm_netlist

end module friction_afm_netlist

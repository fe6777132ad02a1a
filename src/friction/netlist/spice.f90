!> The paper's Network Simulation Method (§5) as a peer of the kernel: the
!> scene of a job written as a SPICE netlist for ngspice.
!>
!> Every state variable is the voltage of a 1 F capacitor fed by a
!> behavioural current source equal to its time derivative, so the capacitor
!> integrates it (V = ∫ I dt); the nonlinear terms (friction law, surface
!> force) are expressions of those voltages inside the sources.  This is the
!> nodal form of the paper's networks: where the paper lets the current of a
!> 1 H coil carry a velocity and sums the force terms as voltages in series,
!> a capacitor voltage carries it here and the terms sum as currents into
!> the node; the equations are the same (Kirchhoff's current law instead of
!> the voltage law).  Simulated time is the scene's time: τ for the brake,
!> seconds for the microscope.
!>
!> Scenes written:
!> - the brake, Eq. 10, with the regularized arctan law (a switched input is
!>   written as the arctan law with its epsilon_prime, and the caller is told);
!> - one microscope scan line (line 0, trace) over NaF (Eq. 1) or HOPG (Eq. 2).
!> A Lennard-Jones lattice sum (Eq. 3) is refused: hundreds of pair terms in
!> behavioural sources, re-derived at every Newton iteration, are impractical.
!>
!> The netlist's .control block runs the transient analysis, writes the
!> waveforms with wrdata (one time column, a header line of names, 16
!> significant digits) and reports ngspice's own analysis time (rusage).
!>
!> Tolerances (&integrator): reltol = rtol; vntol = chgtol = atol, since
!> every state is a capacitor voltage (and, at 1 F, its charge) in the
!> state's unit, as atol is for the kernel; abstol = atol on the currents,
!> the derivatives.  Integration is trapezoidal (ngspice's default; on the
!> brake Gear order 2 was half as accurate at the same reltol).  The step is
!> capped at the output interval so the waveform resolves the samples.
module friction_netlist_spice
   use friction_kinds, only: wp, pi, ev_per_angstrom_to_nn, kg_to_internal, n_per_m_to_internal, &
      & ns_per_m_to_internal
   use friction_error, only: error_type, fatal_error, error_input, error_io
   use friction_strings, only: rtoa
   use friction_input, only: job_config
   use friction_files, only: rename_file, remove_file
   use friction_brake_config, only: brake_config, model_switched
   use friction_afm_config, only: afm_config
   use friction_afm_scan, only: support_across
   implicit none
   private

   public :: spice_netlist

   character(len=*), parameter :: nl = new_line('a')

contains

   !> The netlist of the job's scene as text.  `data_file` is the file the
   !> netlist's wrdata writes (relative to where ngspice runs).  `note` is
   !> set when the netlist departs from the input in a way the user should
   !> hear about (a switched brake written as the arctan law); else empty.
   subroutine spice_netlist(config, data_file, version, text, note, error)
      type(job_config), intent(in) :: config
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error

      note = ''
      if (config%sweep%enabled) then
         call fatal_error(error, '--netlist writes one scene: a &sweep group is not supported '// &
            & '(write one point with an override file instead)', error_input)
         return
      end if
      if (trim(config%scene) == 'brake') then
         call brake_netlist(config%brake, data_file, version, text, note, error)
      else
         call afm_netlist(config%afm, data_file, version, text, error)
      end if
   end subroutine spice_netlist

   !> Eq. 10 with the arctan law; states x, v = x', y, w = y' in m and m/τ.
   subroutine brake_netlist(c, data_file, version, text, note, error)
      type(brake_config), intent(in) :: c
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: law

      associate (p => c%params)
         law = '* Friction law: the regularized arctan law of Eq. 10 (epsilon_prime = '//num(p%epsilon_prime)//').'
         if (trim(c%model) == model_switched) then
            ! The arctan law carries one friction coefficient: a static one
            ! above the kinetic one has no counterpart in it.
            if (p%mu_s /= p%mu) then
               call fatal_error(error, "--netlist: &brake model = 'switched' with mu_s = "//rtoa(p%mu_s) &
                  & //' /= mu = '//rtoa(p%mu)//': the network has the arctan law of Eq. 10, which has one ' &
                  & //"friction coefficient; use model = 'regularized' (or mu_s = mu)", error_input)
               return
            end if
            if (.not. (p%epsilon_prime > 0.0_wp)) then
               call fatal_error(error, "--netlist: &brake model = 'switched' is written as the arctan law, " &
                  & //'which needs epsilon_prime > 0 (it is '//rtoa(p%epsilon_prime)//')', error_input)
               return
            end if
            note = "model = 'switched' written as the regularized arctan law of Eq. 10 with epsilon_prime = " &
               & //rtoa(p%epsilon_prime)//"; compare it with model = 'regularized'"
            law = law//nl// &
               & "* The input has model = 'switched' (stick/slip decision of Fig. 10).  It is written as the" &
               & //nl//'* arctan law with the epsilon_prime above, which approaches the switched model as' &
               & //nl//'* epsilon_prime grows: the paper''s switches need a stick state with x'' = v''_dr exactly,' &
               & //nl//'* which voltage-controlled switches (finite on/off resistance, hysteresis) only' &
               & //nl//"* approximate.  Its kernel counterpart is &brake model = 'regularized'."
         end if
         text = '* friction '//version//': network model of the Girling brake (paper §4, §5.2, Eq. 10)'//nl &
            & //'* Written by friction --netlist.  Run:  ngspice -b THIS_FILE   (writes '//data_file//')'//nl &
            & //'*'//nl &
            & //'* x'''' + 2x - y = -mu N'' (2/pi) atan(eps'' v_rel) / (1 + delta'' |v_rel|),'//nl &
            & //'* xi y'''' - x + kappa y = 0,   N'' = (1 - kappa) y + g'',   v_rel = x'' - v''_dr.'//nl &
            & //law//nl &
            & //'* Each state is the voltage of a 1 F capacitor integrating the current of a behavioural'//nl &
            & //'* source equal to its derivative (the nodal form of the paper''s coil network).'//nl &
            & //'* Time: tau - t_start (the kernel''s tau of the first output point is t_start = ' &
            & //num(c%t_start)//').'//nl &
            & //'* Nodes: x, y in m; v = x'', w = y'' in m per unit tau.'//nl &
            & //'* '//data_file//': columns time x v y w, one header line of names.'//nl &
            & //'* ngspice''s first saved point is after its first step, not at time 0 (the initial state).'//nl &
            & //'*'//nl &
            & //'.param xi = '//num(p%xi)//nl &
            & //'.param kappa = '//num(p%kappa)//nl &
            & //'.param g_prime = '//num(p%g_prime)//nl &
            & //'.param mu = '//num(p%mu)//nl &
            & //'.param epsilon_prime = '//num(p%epsilon_prime)//nl &
            & //'.param delta_prime = '//num(p%delta_prime)//nl &
            & //'.param v_dr = '//num(p%v_dr)//nl &
            & //'* initial state (paper §4.1): x0, x'' = v''_dr + v_rel0, y0, w0'//nl &
            & //'Cx x 0 1 IC='//num(c%x0)//nl &
            & //'Cv v 0 1 IC='//num(p%v_dr + c%v_rel0)//nl &
            & //'Cy y 0 1 IC='//num(c%y0)//nl &
            & //'Cw w 0 1 IC='//num(c%w0)//nl &
            & //'* x'' = v,  y'' = w'//nl &
            & //'Bx 0 x I=V(v)'//nl &
            & //'By 0 y I=V(w)'//nl &
            & //'* v'' = -(2x - y) + friction (E1 and E2 of Fig. 6),  w'' = (x - kappa y)/xi (E1A)'//nl &
            & //'Bv 0 v I=-(2*V(x) - V(y)) - mu*((1 - kappa)*V(y) + g_prime)*(2/pi)' &
            & //'*atan(epsilon_prime*(V(v) - v_dr))/(1 + delta_prime*abs(V(v) - v_dr))'//nl &
            & //'Bw 0 w I=(V(x) - kappa*V(y))/xi'//nl &
            & //tolerances(c%solver%rtol, c%solver%atol)//nl &
            & //'.tran '//num(c%dt_out)//' '//num(c%t_end - c%t_start)//' 0 '//num(c%dt_out)//' uic'//nl &
            & //'.control'//nl &
            & //'set wr_singlescale'//nl &
            & //'set wr_vecnames'//nl &
            & //'option numdgt=15'//nl &
            & //'run'//nl &
            & //'let x = v(x)'//nl &
            & //'let v = v(v)'//nl &
            & //'let y = v(y)'//nl &
            & //'let w = v(w)'//nl &
            & //'wrdata '//data_file//' x v y w'//nl &
            & //control_end()
      end associate
   end subroutine brake_netlist

   !> Line 0 of the map, trace: Eq. 4 in 2D with the tip's absolute position
   !> as state (as the paper: x_t from the integrated current, x_M = v t).
   !> Internal units (friction_kinds): Å, eV, s; forces out in nN.
   subroutine afm_netlist(c, data_file, version, text, error)
      type(afm_config), intent(in) :: c
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: gradient_x, gradient_y, surface
      real(wp) :: along(3), start(3), offset(c%ny), sample_time, trip_time

      select case (trim(c%potential))
      case ('naf')
         surface = '* Surface: NaF(001), Eq. 1: V = -v0 cos(qx x) cos(qy y), qx = 2 pi/ax, qy = 2 pi/ay.'//nl &
            & //'.param v0 = '//num(c%v0)//nl &
            & //'.param qx = '//num(2.0_wp * pi / c%ax)//nl &
            & //'.param qy = '//num(2.0_wp * pi / c%ay)
         gradient_x = 'v0*qx*sin(qx*V(xt))*cos(qy*V(yt))'
         gradient_y = 'v0*qy*cos(qx*V(xt))*sin(qy*V(yt))'
      case ('hopg')
         surface = '* Surface: HOPG, Eq. 2: V = -v0 [2 cos(qx x) cos(qy y) + cos(2 qy y)],'//nl &
            & //'* qx = 2 pi/a, qy = 2 pi/(a sqrt 3).'//nl &
            & //'.param v0 = '//num(c%v0)//nl &
            & //'.param qx = '//num(2.0_wp * pi / c%a)//nl &
            & //'.param qy = '//num(2.0_wp * pi / (c%a * sqrt(3.0_wp)))
         gradient_x = '2*v0*qx*sin(qx*V(xt))*cos(qy*V(yt))'
         gradient_y = '2*v0*qy*(cos(qx*V(xt))*sin(qy*V(yt)) + sin(2*qy*V(yt)))'
      case ('lj')
         call fatal_error(error, "--netlist: &surface potential = 'lj' (the graphite Lennard-Jones lattice sum, " &
            & //'Eq. 3) is not supported: a sum over hundreds of atoms as behavioural sources is impractical ' &
            & //"in SPICE; the network model covers 'naf' and 'hopg'", error_input)
         return
      case default
         call fatal_error(error, "--netlist: unknown potential '"//trim(c%potential)//"'", error_input)
         return
      end select

      along = c%scan_direction()
      offset = support_across(c)
      ! Line 0 starts lead_in before its first sample, as the kernel's trace.
      start = [c%origin_x, c%origin_y, 0.0_wp] + offset(1) * c%across_direction() - c%lead_in * along
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
         & //'Bvx 0 vx I=(kx*(xs + vmx*time - V(xt)) - '//gradient_x//' - cx*V(vx))/mass'//nl &
         & //'Bvy 0 vy I=(ky*(ys + vmy*time - V(yt)) - '//gradient_y//' - cy*V(vy))/mass'//nl &
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

   !> .options from &integrator rtol, atol (see the module's comment).
   function tolerances(rtol, atol) result(text)
      real(wp), intent(in) :: rtol, atol
      character(len=:), allocatable :: text

      text = '* Tolerances from &integrator: reltol = rtol; vntol = chgtol = atol (the states are 1 F' &
         & //nl//'* capacitor voltages, in the units of the kernel''s atol); abstol = atol (their derivatives).' &
         & //nl//'.options reltol='//num(rtol)//' vntol='//num(atol)//' chgtol='//num(atol)//' abstol=' &
         & //num(atol)//' method=trap'
   end function tolerances

   !> The end of the .control block: ngspice's own timing, then quit.
   function control_end() result(text)
      character(len=:), allocatable :: text

      text = '* ngspice''s own timing: "Transient analysis time = ... " (seconds) on stdout'//nl &
         & //'rusage trantime traniter tranpoints accept rejected'//nl &
         & //'quit'//nl &
         & //'.endc'//nl &
         & //'.end'//nl
   end function control_end

   !> A real with 17 significant digits (round trip exact), no blanks.
   pure function num(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer

      write (buffer, '(es24.16e3)') x
      text = trim(adjustl(buffer))
   end function num

end module friction_netlist_spice

!> The paper's Network Simulation Method (§5) as a peer of the kernel: what
!> every scene's SPICE netlist for ngspice shares (each scene writes its own:
!> afm/netlist.f90, brake/netlist.f90).
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
   use friction_kinds, only: wp
   implicit none
   private

   public :: nl, tolerances, control_end, num

   character(len=*), parameter :: nl = new_line('a')

contains

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

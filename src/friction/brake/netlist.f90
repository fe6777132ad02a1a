!> The brake, Eq. 10, with the regularized arctan law as a SPICE netlist for
!> ngspice (docs: netlist); a switched input is written as the arctan law
!> with its epsilon_prime, and the caller is told.  The conventions shared by
!> every scene's netlist are in netlist/spice.f90.
module friction_brake_netlist
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: rtoa
   use friction_checks, only: config_checker
   use friction_netlist_spice, only: nl, tolerances, control_end, num
   use friction_brake_config, only: brake_config
   implicit none
   private

   public :: brake_netlist

contains

   !> Eq. 10 with the arctan law; states x, v = x', y, w = y' in m and m/τ.
   !> A brake with a law is refused naming where &brake model was set
   !> (`origins`: the input's).
   subroutine brake_netlist(c, data_file, version, text, note, error, origins)
      type(brake_config), intent(in) :: c
      character(len=*), intent(in) :: data_file, version
      character(len=:), allocatable, intent(out) :: text, note
      type(error_type), allocatable, intent(out) :: error
      type(config_checker), intent(in), optional :: origins
      type(config_checker) :: refusal
      character(len=:), allocatable :: law

      note = ''   ! (a note only for the switched model; the caller reads it always)
      if (c%uses_law()) then
         ! The network is Eq. 10's; a law's states and exact stick have no element in it.
         if (present(origins)) refusal = origins
         if (allocated(refusal%error)) deallocate (refusal%error)
         call refusal%reject('brake', 'model', "'law'", "--netlist: no netlist with &law model = '" &
            & //trim(c%law%model)//"': the network is written for the arctan law of Eq. 10 only; use &brake " &
            & //"model = 'regularized' (its mu, epsilon_prime and delta_prime) for one")
         call move_alloc(refusal%error, error)
         return
      end if
      associate (p => c%params)
         law = '* Friction law: the regularized arctan law of Eq. 10 (epsilon_prime = '//num(p%epsilon_prime)//').'
         if (c%switched()) then
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

end module friction_brake_netlist

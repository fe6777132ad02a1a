!> &thermal: the microscope at a temperature (README: Friction at a
!> temperature).  At temperature = 0 (the default) the program is the
!> deterministic one, bit for bit, and the other variables are not used.
!> At T > 0 every trip of the support is run `realizations` times with
!> independent noise, each from the random stream of its (seed, line,
!> trip, realization) (friction_random), by model = 'langevin' (the
!> Langevin tip, friction_afm_langevin, at a fixed step) or 'kramers' (the
!> thermal reduced model: the tip in a minimum of its energy, jumping over
!> the saddle ahead at Kramers–Langer rates by kinetic Monte Carlo,
!> friction_afm_kramers_trip); the output is the mean of every sample
!> over the realizations with its standard error.
!>
!> This module holds the group's variables and the checks that need no
!> other group; the checks against the tip and the surface (an undamped
!> axis, the step's stability limit) are afm_config%validate's.  Also the
!> running mean and variance over realizations (Welford's update: the same
!> numbers whatever the rank, as every line's realizations run in order on
!> one rank).
module friction_afm_thermal
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, i8
   use friction_strings, only: itoa, rtoa, quoted
   use friction_parameters, only: configurable, parameter_visitor
   use friction_checks, only: config_checker
   implicit none
   private

   public :: thermal_settings, thermal_model_names, welford_add, welford_sem

   !> The highest temperature accepted, K.
   real(wp), parameter :: max_temperature = 1.0e5_wp

   !> &thermal model: the Langevin tip, or the thermal reduced model (Kramers
   !> rates and kinetic Monte Carlo, friction_afm_kramers).
   character(len=*), parameter :: thermal_model_names(2) = [character(len=8) :: 'langevin', 'kramers']

   type, extends(configurable) :: thermal_settings
      real(wp) :: temperature = 0.0_wp       !! K; 0: the deterministic program
      integer(i8) :: seed = 1_i8              !! the random streams' seed
      integer :: realizations = 1             !! independent repetitions of every line
      character(len=16) :: model = 'langevin'
      real(wp) :: time_step = 0.0_wp          !! s; 0: from the tip's fastest time scale
      !> Hz; > 0: the damping cx = cy that gives this Kramers prefactor
      !> (afm_config's attempt_damping); 0: &tip's cx, cy
      real(wp) :: attempt_frequency = 0.0_wp
   contains
      procedure :: visit
      procedure :: validate
      procedure :: enabled
      procedure :: reduced
   end type thermal_settings

contains

   subroutine visit(self, v)
      class(thermal_settings), intent(inout) :: self
      type(parameter_visitor), intent(inout) :: v

      call v%begin_group('thermal')
      call v%item('temperature', self%temperature, 'K')
      call v%item('seed', self%seed)
      call v%item('realizations', self%realizations)
      call v%item('model', self%model, fold=.true.)
      call v%item('time_step', self%time_step, 's')
      call v%item('attempt_frequency', self%attempt_frequency, 'Hz')
      call v%end_group()
   end subroutine visit

   !> Whether the thermal model is the reduced one ('kramers': jumps between
   !> minima at Kramers' rates) rather than the Langevin tip.
   pure logical function reduced(self)
      class(thermal_settings), intent(in) :: self

      reduced = trim(self%model) == 'kramers'
   end function reduced

   !> T > 0: the thermal model runs.
   pure logical function enabled(self)
      class(thermal_settings), intent(in) :: self

      enabled = self%temperature > 0.0_wp
   end function enabled

   !> The checks of the group alone.
   subroutine validate(self, c)
      class(thermal_settings), intent(in) :: self
      type(config_checker), intent(inout) :: c

      call c%finite('thermal', 'temperature', self%temperature)
      call c%nonnegative('thermal', 'temperature', self%temperature, 'K; 0 for the deterministic tip')
      ! Every crystal has melted long before (1e300 K ran, with forces of 1e148 nN).
      if (self%temperature > max_temperature) call c%reject('thermal', 'temperature', rtoa(self%temperature), &
         & 'must be <= '//rtoa(max_temperature)//' K (a tip over a crystal: every crystal melts below 5000 K)')
      if (self%realizations < 1) call c%reject('thermal', 'realizations', itoa(self%realizations), &
         & 'must be >= 1 (independent repetitions of every line)')
      if (.not. any(thermal_model_names == self%model)) then
         call c%reject('thermal', 'model', "'"//trim(self%model)//"'", 'unknown thermal model (known: ' &
            & //quoted(thermal_model_names)//')')
      else if (self%reduced() .and. self%enabled() .and. self%time_step /= 0.0_wp) then
         call c%reject('thermal', 'time_step', rtoa(self%time_step), "is not used by model = 'kramers' " &
            & //"(it takes no time steps: the jumps are drawn from the escape rate); leave it 0")
      end if
      call c%finite('thermal', 'time_step', self%time_step)
      call c%nonnegative('thermal', 'time_step', self%time_step, 's; 0 chooses it')
      call c%finite('thermal', 'attempt_frequency', self%attempt_frequency)
      call c%nonnegative('thermal', 'attempt_frequency', self%attempt_frequency, "Hz; 0: &tip's cx, cy")
   end subroutine validate

   !> Welford's update of the running mean and sum of squared deviations
   !> with the n-th value x (n >= 1).
   elemental subroutine welford_add(mean, m2, x, n)
      real(wp), intent(inout) :: mean, m2
      real(wp), intent(in) :: x
      integer, intent(in) :: n
      real(wp) :: delta

      if (n == 1) then
         mean = x
         m2 = 0.0_wp
         return
      end if
      delta = x - mean
      mean = mean + delta / real(n, wp)
      m2 = m2 + delta * (x - mean)
   end subroutine welford_add

   !> The standard error of the mean of n values with sum of squared
   !> deviations m2: sqrt(m2/(n - 1)/n); NaN for one value.
   elemental function welford_sem(m2, n) result(sem)
      real(wp), intent(in) :: m2
      integer, intent(in) :: n
      real(wp) :: sem

      if (n < 2) then
         sem = ieee_value(1.0_wp, ieee_quiet_nan)
      else
         sem = sqrt(m2 / real(n - 1, wp) / real(n, wp))
      end if
   end function welford_sem

end module friction_afm_thermal

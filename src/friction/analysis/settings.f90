!> What a user chooses about the chaos diagnostics (README: &analysis), in
!> the units of the scene's time.  Scene-independent: a scene maps `series`
!> to one of its variables and `section` to one of its sections.
module friction_analysis_settings
   use friction_kinds, only: wp
   use friction_analysis_spectrum, only: window_hann
   implicit none
   private

   public :: analysis_settings, section_names

   character(len=*), parameter :: section_names(3) = [character(len=13) :: 'none', 'stick_to_slip', 'w_zero_up']

   type :: analysis_settings
      ! Spectrum (Fig. 13)
      logical :: spectrum = .false.
      character(len=8) :: series = 'x'             !! the variable analysed (spectrum, Rosenstein)
      real(wp) :: window_start = 100.0_wp          !! analysis window in time (spectrum, Rosenstein)
      real(wp) :: window_end = 1000.0_wp
      character(len=8) :: window = window_hann     !! 'hann' or 'none'
      integer :: welch_segments = 1                !! half-overlapping segments averaged
      ! Poincaré maps (Fig. 14)
      logical :: poincare = .false.
      real(wp) :: strobe_period = 0.0_wp           !! 0: 1 / peak frequency of the spectrum
      real(wp) :: strobe_start = 0.0_wp
      real(wp) :: strobe_end = 0.0_wp              !! 0: the end of the run
      character(len=16) :: section = 'stick_to_slip'
      ! Maximum Lyapunov exponent from the equations (Benettin)
      logical :: lyapunov = .false.
      real(wp) :: lyapunov_transient = 100.0_wp    !! from the start of the run
      real(wp) :: lyapunov_duration = 0.0_wp       !! 0: to the end of the run
      real(wp) :: lyapunov_renormalise = 1.0_wp
      real(wp) :: lyapunov_d0 = 1.0e-8_wp
      ! ... and from the series (Rosenstein); lengths in samples of the strided series
      logical :: rosenstein = .false.
      integer :: rosenstein_stride = 4
      integer :: rosenstein_dimension = 4
      integer :: rosenstein_delay = 8
      integer :: rosenstein_theiler = 35
      integer :: rosenstein_horizon = 150
      integer :: rosenstein_fit_start = 0
      integer :: rosenstein_fit_end = 50
   end type analysis_settings

end module friction_analysis_settings

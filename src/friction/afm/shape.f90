!> The barrier shape of a one-dimensional Fourier landscape (&surface
!> potential = 'fourier') for the map's tip and scan: where the tip's
!> minimum vanishes on the trace and on the retrace, the barrier's exponent
!> and prefactor there, ΔE = μ (F_c - F)^(3/2), and Sang, Dubé and Grant's
!> β = 1/μ of F = F_c - (β k_B T ln(v_c/v))^(2/3), with F the friction the
!> map reports (docs/physics.md, Barrier shapes beyond the sinusoid).
module friction_afm_shape
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, ev_per_angstrom_to_nn, n_per_m_to_internal, deg_to_rad
   use friction_value_text, only: shortest
   use friction_surface_fourier, only: fourier_potential, new_fourier_potential, fold_shape, barrier_shape
   use friction_output_h5, only: h5_file
   use friction_afm_config, only: afm_config, fourier_harmonics
   implicit none
   private

   public :: landscape_shape, shape_of, write_shape, shape_summary

   !> The shape on the trace (1) and the retrace (2), in the output's units,
   !> and for the map's friction, the mean of the two trips' forces.
   type :: landscape_shape
      real(wp) :: position(2) = 0.0_wp     !! the fold x_c, Å (within one period)
      real(wp) :: support(2) = 0.0_wp      !! the support there, X_c along x, Å
      real(wp) :: third(2) = 0.0_wp        !! V'''(x_c), eV/Å³
      real(wp) :: jump(2) = 0.0_wp         !! from the fold to the landing minimum, Å
      integer :: folds(2) = 0              !! folds per cycle of the motion
      real(wp) :: friction(2) = 0.0_wp     !! F_c: the trip's mean force along the scan at T = 0, slow limit, nN
      real(wp) :: prefactor(2) = 0.0_wp    !! μ, eV/nN^(3/2)
      real(wp) :: beta(2) = 0.0_wp         !! 1/μ, nN^(3/2)/eV
      real(wp) :: exponent = 0.0_wp        !! 3/2 at a fold, NaN without one
      real(wp) :: line_friction = 0.0_wp   !! (F_c trace + F_c retrace)/2, nN
      real(wp) :: line_beta = 0.0_wp       !! the map's friction's β, nN^(3/2)/eV
      character(len=:), allocatable :: why !! '' when defined
   end type landscape_shape

contains

   !> The shape for the settings (potential = 'fourier'): the fold met by the
   !> tip on its spring kx when the support moves along +x (trace, for
   !> cos(angle) > 0) and along -x (retrace).  Along the scan the force is
   !> |cos(angle)| times the force along x and the support travels 1/|cos|
   !> as far, so F_c scales with |cos| and μ with |cos|^(-3/2).  The map's
   !> friction, the mean of the two trips, follows Sang's law with
   !> β^(2/3) the mean of the trips' β^(2/3) (for equal v_c).
   function shape_of(config) result(shape)
      type(afm_config), intent(in) :: config
      type(landscape_shape) :: shape
      type(fourier_potential) :: potential
      type(barrier_shape) :: fold
      real(wp) :: k, along, nan, scale
      integer :: trip, n, direction

      nan = ieee_value(0.0_wp, ieee_quiet_nan)
      shape%why = ''
      n = fourier_harmonics(config)
      potential = new_fourier_potential(config%cosine(1:n), config%sine(1:n), config%ax)
      k = config%kx * n_per_m_to_internal
      along = cos(config%angle * deg_to_rad)
      shape%exponent = 1.5_wp
      do trip = 1, 2
         direction = merge(1, -1, (along >= 0.0_wp) .eqv. (trip == 1))
         fold = fold_shape(potential, k, direction)
         shape%position(trip) = fold%fold
         shape%support(trip) = fold%support
         shape%third(trip) = fold%third
         shape%jump(trip) = fold%jump
         shape%folds(trip) = fold%folds
         shape%friction(trip) = abs(along) * fold%dissipated / fold%travel * ev_per_angstrom_to_nn
         ! μ in eV/(eV/Å)^(3/2) along x, to nN along the scan.
         scale = (abs(along) * ev_per_angstrom_to_nn)**1.5_wp
         shape%prefactor(trip) = fold%prefactor / scale
         shape%beta(trip) = scale / fold%prefactor
         if (len(fold%why) > 0 .and. len(shape%why) == 0) shape%why = trim(merge('trace  ', 'retrace', trip == 1)) &
            & //': '//fold%why
         if (.not. (abs(along) > 1.0e-12_wp)) shape%why = 'the scan runs across the row (angle 90 degrees): ' &
            & //'no stick-slip along it'
      end do
      shape%why = trim(shape%why)
      if (len(shape%why) > 0) then
         shape%exponent = nan
         shape%prefactor = nan
         shape%beta = nan
      end if
      shape%line_friction = 0.5_wp * sum(shape%friction)
      shape%line_beta = (0.5_wp * sum(shape%beta**(2.0_wp / 3.0_wp)))**1.5_wp
   end function shape_of

   !> /surface: the coefficients and the barrier's shape (docs/output.md).
   subroutine write_shape(file, config)
      type(h5_file), intent(inout) :: file
      type(afm_config), intent(in) :: config
      type(landscape_shape) :: shape
      integer :: n

      shape = shape_of(config)
      n = fourier_harmonics(config)
      call file%create_group('/surface')
      call file%write_vector('/surface/cosine', config%cosine(1:n), 'eV')
      call file%write_vector('/surface/sine', config%sine(1:n), 'eV')
      call file%write_attribute_real('/surface', 'barrier_exponent', shape%exponent)
      call file%write_attribute_real('/surface', 'critical_friction', shape%line_friction, 'nN')
      call file%write_attribute_real('/surface', 'beta', shape%line_beta, 'nN^1.5/eV')
      if (len(shape%why) > 0) call file%write_attribute_text('/surface', 'shape_note', shape%why)
      call file%create_group('/surface/fold')
      call file%write_vector('/surface/fold/position', shape%position, 'angstrom')
      call file%write_vector('/surface/fold/support', shape%support, 'angstrom')
      call file%write_vector('/surface/fold/third_derivative', shape%third, 'eV/angstrom^3')
      call file%write_vector('/surface/fold/jump', shape%jump, 'angstrom')
      call file%write_integer_vector('/surface/fold/folds', shape%folds)
      call file%write_vector('/surface/fold/friction', shape%friction, 'nN')
      call file%write_vector('/surface/fold/prefactor', shape%prefactor, 'eV/nN^1.5')
      call file%write_vector('/surface/fold/beta', shape%beta, 'nN^1.5/eV')
   end subroutine write_shape

   !> One clause for the run's summary line.
   function shape_summary(config) result(text)
      type(afm_config), intent(in) :: config
      character(len=:), allocatable :: text
      type(landscape_shape) :: shape

      shape = shape_of(config)
      if (len(shape%why) > 0) then
         text = 'barrier shape: none ('//shape%why//')'
      else
         text = 'barrier shape: Delta E = mu (F_c - F)^1.5, beta = 1/mu = '//trim(shortest(round(shape%line_beta))) &
            & //' nN^1.5/eV, F_c = '//trim(shortest(round(shape%line_friction)))//' nN'
      end if
   end function shape_summary

   !> Four significant digits for the summary line.
   pure real(wp) function round(x)
      real(wp), intent(in) :: x
      real(wp) :: scale

      round = x
      if (.not. (abs(x) > 0.0_wp .and. abs(x) <= huge(x))) return
      scale = 10.0_wp**(3 - floor(log10(abs(x))))
      round = anint(x * scale) / scale
   end function round

end module friction_afm_shape

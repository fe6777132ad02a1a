!> Rosenstein's exponent of a scene's series into its Lyapunov group
!> (docs/output.md): the exponent, its settings and the divergence curve,
!> the same for every scene that computes it.
module friction_output_rosenstein
   use friction_kinds, only: wp, i8
   use friction_analysis_settings, only: analysis_settings
   use friction_analysis_lyapunov_series, only: rosenstein_result
   use friction_output_h5, only: h5_file
   implicit none
   private

   public :: write_rosenstein

contains

   !> `group` exists; `rate_unit` is the exponent's unit and `time_unit` the
   !> divergence's times' (the brake's 1/tau and 1, the machine's 1/s and s);
   !> `spacing_unit`, if present, the sample spacing's.
   subroutine write_rosenstein(file, group, a, series, series_dt, rate_unit, time_unit, spacing_unit)
      type(h5_file), intent(inout) :: file
      character(len=*), intent(in) :: group, rate_unit, time_unit
      character(len=*), intent(in), optional :: spacing_unit
      type(analysis_settings), intent(in) :: a
      type(rosenstein_result), intent(in) :: series
      real(wp), intent(in) :: series_dt

      call file%write_attribute_real(group, 'rosenstein_exponent', series%exponent, rate_unit)
      ! OpenTSTool's largelyap unit: log2 per sample of the series.
      call file%write_attribute_real(group, 'rosenstein_log2_per_sample', series%exponent * series_dt / log(2.0_wp))
      call file%write_attribute_text(group, 'rosenstein_series', trim(a%series))
      if (present(spacing_unit)) then
         call file%write_attribute_real(group, 'rosenstein_sample_spacing', series_dt, spacing_unit)
      else
         call file%write_attribute_real(group, 'rosenstein_sample_spacing', series_dt)
      end if
      call file%write_attribute_integer(group, 'rosenstein_stride', int(a%rosenstein_stride, i8))
      call file%write_attribute_integer(group, 'rosenstein_dimension', int(a%rosenstein_dimension, i8))
      call file%write_attribute_integer(group, 'rosenstein_delay', int(a%rosenstein_delay, i8))
      call file%write_attribute_integer(group, 'rosenstein_theiler', int(a%rosenstein_theiler, i8))
      call file%write_attribute_integer(group, 'rosenstein_horizon', int(a%rosenstein_horizon, i8))
      call file%write_attribute_integer(group, 'rosenstein_fit_start', int(a%rosenstein_fit_start, i8))
      call file%write_attribute_integer(group, 'rosenstein_fit_end', int(a%rosenstein_fit_end, i8))
      call file%write_vector(group//'/rosenstein_time', series%time, time_unit)
      call file%write_vector(group//'/rosenstein_divergence', series%divergence, '1')
      call file%write_attribute_text(group//'/rosenstein_divergence', 'long_name', &
         & 'mean natural log of the distance between neighbours, the distance in the unit of the series')
      call file%attach_scales(group//'/rosenstein_divergence', [group//'/rosenstein_time'])
   end subroutine write_rosenstein

end module friction_output_rosenstein

!> The one place that knows the concrete friction laws: a law from its
!> name, with the &law parameters it was made from.
module friction_law_factory
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: quoted
   use friction_checks, only: config_checker
   use friction_law, only: sliding_law
   use friction_law_settings, only: law_settings, law_group
   use friction_law_coulomb, only: coulomb_law
   use friction_law_arctan, only: arctan_law
   use friction_law_stribeck, only: stribeck_law
   use friction_law_karnopp, only: karnopp_law
   use friction_law_dahl, only: dahl_law
   use friction_law_lugre, only: lugre_law
   use friction_law_elastoplastic, only: elastoplastic_law
   use friction_law_rate_state, only: rate_state_law
   use friction_law_table, only: table_law
   use friction_law_gms, only: gms_law
   implicit none
   private

   public :: law_names, new_law, check_law, make_law

   !> &law model = '...' (the first is the default).
   character(len=*), parameter :: law_names(10) = [character(len=13) :: 'coulomb', 'arctan', 'stribeck', &
      & 'karnopp', 'dahl', 'lugre', 'elastoplastic', 'rate_state', 'table', 'gms']

contains

   !> A law of that name with the parameters p; unallocated if there is none.
   subroutine new_law(p, law)
      type(law_settings), intent(in) :: p
      class(sliding_law), allocatable, intent(out) :: law

      select case (trim(p%model))
      case ('coulomb')
         allocate (coulomb_law :: law)
      case ('arctan')
         allocate (arctan_law :: law)
      case ('stribeck')
         allocate (stribeck_law :: law)
      case ('karnopp')
         allocate (karnopp_law :: law)
      case ('dahl')
         allocate (dahl_law :: law)
      case ('lugre')
         allocate (lugre_law :: law)
      case ('elastoplastic')
         allocate (elastoplastic_law :: law)
      case ('rate_state')
         allocate (rate_state_law :: law)
      case ('table')
         allocate (table_law :: law)
      case ('gms')
         allocate (gms_law :: law)
      case default
         return
      end select
      law%p = p
   end subroutine new_law

   !> The name, then the law's own parameters; the first bad value to c.
   subroutine check_law(p, c)
      type(law_settings), intent(in) :: p
      type(config_checker), intent(inout) :: c
      class(sliding_law), allocatable :: law

      call new_law(p, law)
      if (.not. allocated(law)) then
         call c%reject(law_group, 'model', "'"//trim(p%model)//"'", 'unknown friction law (known: ' &
            & //quoted(law_names)//')')
         return
      end if
      call law%check(c)
   end subroutine check_law

   !> The law ready to compute (its table read): checked settings expected,
   !> but a file that changed since is an error.
   subroutine make_law(p, law, error)
      type(law_settings), intent(in) :: p
      class(sliding_law), allocatable, intent(out) :: law
      type(error_type), allocatable, intent(out) :: error

      call new_law(p, law)
      if (.not. allocated(law)) then
         call fatal_error(error, '&'//law_group//": model = '"//trim(p%model)//"': unknown friction law (known: " &
            & //quoted(law_names)//')', error_input)
         return
      end if
      call law%prepare(error)
   end subroutine make_law

end module friction_law_factory

!> Random streams for thermal noise, on GSL's generators (random_c.c).
!>
!> One stream per (seed, line, trip, realization): the tuple is hashed
!> (splitmix64's mixer, chained over the components) into the generator's
!> state, so a stream depends on its tuple only, never on how many MPI ranks
!> share a map or in which order they compute its lines; and two tuples give
!> streams as independent as two random starting points on the generator's
!> cycle.  No global state: each stream owns its generator, so streams on
!> different threads share nothing.
!>
!> The generator is GSL's taus2 (L'Ecuyer's maximally equidistributed
!> combined Tausworthe, period 2^88):
!>   - speed: 3.5 ns a draw and 6 ns a Gaussian variate in a C loop on the
!>     shared 2-core test machine (9 ns through this module's buffer, under
!>     load: scripts/benchmark_langevin), among the fastest of GSL's
!>     generators that pass the usual batteries (mt19937: 7 and 10 ns;
!>     ranlxd1: 80 and 87 ns, most of the 100 ns a Langevin step may take);
!>   - state: 3 words (24 bytes), so a stream per trip costs nothing and is
!>     seeded from a 64-bit hash in full (gfsr4, as fast, has a 128 kB
!>     state; mt19937's 2.5 kB would be seeded from 32 bits by gsl_rng_set,
!>     and by the birthday bound tuples collide after ~1e5 streams);
!>   - quality: like mt19937 it fails only the linear-complexity tests of
!>     TestU01 (F2-linear generators), which no Langevin observable sees;
!>   - independence: streams start at hashed points of a 2^88 cycle; n
!>     streams of L draws overlap with probability ~ n² L / 2^88, 3e-6 for a
!>     million streams of 1e9 draws.
!> Gaussian variates by the ziggurat method (gsl_ran_gaussian_ziggurat,
!> the fastest of GSL's), drawn 64 at a time into the stream's buffer.  The
!> sequence of variates a stream returns depends only on the sequence of
!> calls made on it, not on how the caller batches its work.
!>
!> A stream that could not be made (no memory; a GSL whose taus2 state is
!> not laid out as expected) gives an error from init; an uninitialised
!> stream returns NaN, which the integrators report as a numerical error.
!> Copies made by assignment are independent streams with the same state;
!> free (or finalisation) releases the generator.
module friction_random
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_double, c_int, c_int64_t, &
      & c_long
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, i8
   use friction_error, only: error_type, fatal_error, error_internal
   implicit none
   private

   public :: random_stream, stream_hash

   integer, parameter :: buffer_size = 64

   !> A stream of variates for one (seed, line, trip, realization).
   type :: random_stream
      private
      type(c_ptr) :: rng = c_null_ptr
      real(c_double) :: buffer(buffer_size) = 0.0_c_double
      integer :: next = buffer_size + 1   !! next unread buffer entry
   contains
      procedure :: init
      procedure :: gaussian
      procedure :: gaussians
      procedure :: uniform
      procedure :: exponential
      procedure :: raw
      procedure :: ready
      procedure :: free => release
      procedure, private :: assign
      generic :: assignment(=) => assign
      final :: finalize
   end type random_stream

   interface
      function c_rng_new(seed, line, trip, realization) result(r) bind(c, name='friction_rng_new')
         import :: c_ptr, c_int64_t
         integer(c_int64_t), value :: seed, line, trip, realization
         type(c_ptr) :: r
      end function c_rng_new

      function c_rng_clone(source) result(r) bind(c, name='friction_rng_clone')
         import :: c_ptr
         type(c_ptr), value :: source
         type(c_ptr) :: r
      end function c_rng_clone

      subroutine c_rng_free(r) bind(c, name='friction_rng_free')
         import :: c_ptr
         type(c_ptr), value :: r
      end subroutine c_rng_free

      subroutine c_rng_gaussians(r, x, n) bind(c, name='friction_rng_gaussians')
         import :: c_ptr, c_double, c_int
         type(c_ptr), value :: r
         real(c_double), intent(out) :: x(*)
         integer(c_int), value :: n
      end subroutine c_rng_gaussians

      function c_rng_uniform(r) result(u) bind(c, name='friction_rng_uniform')
         import :: c_ptr, c_double
         type(c_ptr), value :: r
         real(c_double) :: u
      end function c_rng_uniform

      function c_rng_raw(r) result(k) bind(c, name='friction_rng_raw')
         import :: c_ptr, c_long
         type(c_ptr), value :: r
         integer(c_long) :: k
      end function c_rng_raw

      function c_rng_hash(seed, line, trip, realization) result(h) bind(c, name='friction_rng_hash')
         import :: c_int64_t
         integer(c_int64_t), value :: seed, line, trip, realization
         integer(c_int64_t) :: h
      end function c_rng_hash
   end interface

contains

   !> The stream of the tuple (seed, line, trip, realization), from its
   !> first variate; a stream already in use is released first.
   subroutine init(self, seed, line, trip, realization, error)
      class(random_stream), intent(inout) :: self
      integer(i8), intent(in) :: seed
      integer, intent(in) :: line, trip, realization
      type(error_type), allocatable, intent(out) :: error

      call self%free()
      self%rng = c_rng_new(int(seed, c_int64_t), int(line, c_int64_t), int(trip, c_int64_t), &
         & int(realization, c_int64_t))
      if (.not. c_associated(self%rng)) then
         call fatal_error(error, 'random stream: the taus2 generator could not be set up '// &
            & '(out of memory, or a GSL whose taus2 state differs from GSL 1.0 to 2.x)', error_internal)
         return
      end if
      self%next = buffer_size + 1
   end subroutine init

   !> The tuple's 64-bit hash, which seeds its stream (for tests).
   function stream_hash(seed, line, trip, realization) result(h)
      integer(i8), intent(in) :: seed
      integer, intent(in) :: line, trip, realization
      integer(i8) :: h

      h = int(c_rng_hash(int(seed, c_int64_t), int(line, c_int64_t), int(trip, c_int64_t), &
         & int(realization, c_int64_t)), i8)
   end function stream_hash

   logical function ready(self)
      class(random_stream), intent(in) :: self

      ready = c_associated(self%rng)
   end function ready

   subroutine refill(self)
      class(random_stream), intent(inout) :: self

      if (c_associated(self%rng)) then
         call c_rng_gaussians(self%rng, self%buffer, int(buffer_size, c_int))
      else
         self%buffer = ieee_value(1.0_c_double, ieee_quiet_nan)
      end if
      self%next = 1
   end subroutine refill

   !> A standard normal variate.
   function gaussian(self) result(x)
      class(random_stream), intent(inout) :: self
      real(wp) :: x

      if (self%next > buffer_size) call refill(self)
      x = self%buffer(self%next)
      self%next = self%next + 1
   end function gaussian

   !> Standard normal variates into x, the same as size(x) calls of gaussian.
   subroutine gaussians(self, x)
      class(random_stream), intent(inout) :: self
      real(wp), intent(out) :: x(:)
      integer :: i

      do i = 1, size(x)
         if (self%next > buffer_size) call refill(self)
         x(i) = self%buffer(self%next)
         self%next = self%next + 1
      end do
   end subroutine gaussians

   !> A uniform variate in (0, 1), straight from the generator (the
   !> Gaussian buffer is not touched).
   function uniform(self) result(u)
      class(random_stream), intent(inout) :: self
      real(wp) :: u

      if (c_associated(self%rng)) then
         u = c_rng_uniform(self%rng)
      else
         u = ieee_value(1.0_wp, ieee_quiet_nan)
      end if
   end function uniform

   !> An exponential variate of mean 1, -ln U: the target of a cumulative
   !> hazard (a jump happens when ∫ r dt reaches it).
   function exponential(self) result(x)
      class(random_stream), intent(inout) :: self
      real(wp) :: x

      x = -log(self%uniform())
   end function exponential

   !> The generator's next raw 32-bit output (for tests of the generator).
   function raw(self) result(k)
      class(random_stream), intent(inout) :: self
      integer(i8) :: k

      k = -1
      if (c_associated(self%rng)) k = int(c_rng_raw(self%rng), i8)
   end function raw

   !> Release the generator; the stream is then uninitialised.
   subroutine release(self)
      class(random_stream), intent(inout) :: self

      if (c_associated(self%rng)) call c_rng_free(self%rng)
      self%rng = c_null_ptr
      self%next = buffer_size + 1
   end subroutine release

   !> A copy with its own generator in the same state.
   subroutine assign(lhs, rhs)
      class(random_stream), intent(inout) :: lhs
      class(random_stream), intent(in) :: rhs

      if (c_associated(lhs%rng, rhs%rng)) return
      call lhs%free()
      if (c_associated(rhs%rng)) lhs%rng = c_rng_clone(rhs%rng)
      lhs%buffer = rhs%buffer
      lhs%next = rhs%next
   end subroutine assign

   subroutine finalize(self)
      type(random_stream), intent(inout) :: self

      call self%free()
   end subroutine finalize

end module friction_random

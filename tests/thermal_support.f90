!> Shared by the thermal test suites (test_random, test_langevin,
!> test_kramers): a tilted cosine (washboard) surface with closed-form
!> stationary points, block averages for the standard error of correlated
!> series, and the tips of inputs/naf.nml.
module thermal_support
   use friction_kinds, only: wp, i8, pi, kg_to_internal, n_per_m_to_internal, ns_per_m_to_internal
   use friction_surface_potential, only: surface_potential
   use friction_surface_naf, only: new_naf_potential
   use friction_afm_tip, only: afm_tip
   implicit none
   private

   public :: tilted_washboard, washboard_points, block_average, naf_tip
   public :: naf_mass, naf_spring, naf_damping

   !> inputs/naf.nml's tip (the paper's §6.1): m = 1e-8 kg, k = 10 N/m,
   !> c = 1e-3 N s/m, in internal units.
   real(wp), parameter :: naf_mass = 1.0e-8_wp * kg_to_internal
   real(wp), parameter :: naf_spring = 10.0_wp * n_per_m_to_internal
   real(wp), parameter :: naf_damping = 1.0e-3_wp * ns_per_m_to_internal

   !> V(r) = -U0 cos(q s) - F s with s = n·r: a tilted cosine along the unit
   !> vector n (in the xy plane), flat across it.
   type, extends(surface_potential) :: tilted_washboard
      real(wp) :: u0 = 0.0_wp       !! eV
      real(wp) :: q = 0.0_wp        !! 2π/a, 1/Å
      real(wp) :: tilt = 0.0_wp     !! F, eV/Å
      real(wp) :: normal(3) = [1.0_wp, 0.0_wp, 0.0_wp]
   contains
      procedure :: energy => washboard_energy
      procedure :: gradient => washboard_gradient
      procedure :: hessian => washboard_hessian
      procedure :: dimensions => washboard_dimensions
   end type tilted_washboard

   !> Block averages of a series of n = blocks × per_block samples: the
   !> mean, and the variance about the overall mean, with standard errors
   !> from the scatter of the block values (blocks much longer than the
   !> integrated autocorrelation time are independent).
   type :: block_average
      integer :: blocks = 0
      integer(i8) :: per_block = 0
      integer(i8) :: count = 0
      real(wp), allocatable :: s1(:), s2(:)
   contains
      procedure :: init => block_init
      procedure :: add => block_add
      procedure :: mean => block_mean
      procedure :: variance => block_variance
   end type block_average

contains

   pure function washboard_energy(self, r) result(v)
      class(tilted_washboard), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v, s

      s = dot_product(self%normal, r)
      v = -self%u0 * cos(self%q * s) - self%tilt * s
   end function washboard_energy

   pure subroutine washboard_gradient(self, r, g)
      class(tilted_washboard), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: s

      s = dot_product(self%normal, r)
      g = (self%u0 * self%q * sin(self%q * s) - self%tilt) * self%normal
   end subroutine washboard_gradient

   pure subroutine washboard_hessian(self, r, h)
      class(tilted_washboard), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: s
      integer :: i, j

      s = dot_product(self%normal, r)
      do j = 1, 3
         do i = 1, 3
            h(i, j) = self%u0 * self%q**2 * cos(self%q * s) * self%normal(i) * self%normal(j)
         end do
      end do
   end subroutine washboard_hessian

   pure function washboard_dimensions(self) result(n)
      class(tilted_washboard), intent(in) :: self
      integer :: n

      n = 2
   end function washboard_dimensions

   !> A washboard of period a (Å) whose forward barrier is barrier (eV) at
   !> tilt ratio f = F/(U0 q) < 1; its minimum s_min, saddle s_saddle (the
   !> barrier ahead, towards +s) and curvature U0 q² cos α at both
   !> (α = asin f): closed forms.
   subroutine washboard_points(a, f, barrier, w, s_min, s_saddle, curvature)
      real(wp), intent(in) :: a, f, barrier
      type(tilted_washboard), intent(out) :: w
      real(wp), intent(out) :: s_min, s_saddle, curvature
      real(wp) :: alpha

      alpha = asin(f)
      w%q = 2.0_wp * pi / a
      w%u0 = barrier / (2.0_wp * cos(alpha) - f * (pi - 2.0_wp * alpha))
      w%tilt = f * w%u0 * w%q
      s_min = alpha / w%q
      s_saddle = (pi - alpha) / w%q
      curvature = w%u0 * w%q**2 * cos(alpha)
   end subroutine washboard_points

   subroutine block_init(self, blocks, samples)
      class(block_average), intent(inout) :: self
      integer, intent(in) :: blocks
      integer(i8), intent(in) :: samples

      self%blocks = blocks
      self%per_block = samples / blocks
      self%count = 0
      if (allocated(self%s1)) deallocate (self%s1, self%s2)
      allocate (self%s1(blocks), self%s2(blocks))
      self%s1 = 0.0_wp
      self%s2 = 0.0_wp
   end subroutine block_init

   !> Add a sample; those beyond blocks × per_block are ignored.
   subroutine block_add(self, x)
      class(block_average), intent(inout) :: self
      real(wp), intent(in) :: x
      integer :: b

      b = int(self%count / self%per_block) + 1
      self%count = self%count + 1
      if (b > self%blocks) return
      self%s1(b) = self%s1(b) + x
      self%s2(b) = self%s2(b) + x * x
   end subroutine block_add

   subroutine block_mean(self, mean, se)
      class(block_average), intent(in) :: self
      real(wp), intent(out) :: mean, se
      real(wp) :: m(self%blocks)

      m = self%s1 / real(self%per_block, wp)
      mean = sum(m) / self%blocks
      se = sqrt(sum((m - mean)**2) / real(self%blocks - 1, wp) / real(self%blocks, wp))
   end subroutine block_mean

   subroutine block_variance(self, variance, se)
      class(block_average), intent(in) :: self
      real(wp), intent(out) :: variance, se
      real(wp) :: m(self%blocks), y(self%blocks), mean, n

      n = real(self%per_block, wp)
      m = self%s1 / n
      mean = sum(m) / self%blocks
      y = self%s2 / n - 2.0_wp * mean * m + mean**2
      variance = sum(y) / self%blocks
      se = sqrt(sum((y - variance)**2) / real(self%blocks - 1, wp) / real(self%blocks, wp))
   end subroutine block_variance

   !> inputs/naf.nml's tip on a NaF surface of amplitude v0 (eV; 0: flat),
   !> in 2D, for the given model, with the support at rest at the origin.
   function naf_tip(model, v0) result(tip)
      integer, intent(in) :: model
      real(wp), intent(in) :: v0
      type(afm_tip) :: tip

      tip%ndim = 2
      tip%model = model
      tip%mass = naf_mass
      tip%spring(1:2) = naf_spring
      tip%damping(1:2) = naf_damping
      allocate (tip%potential, source=new_naf_potential(v0, 4.62_wp, 4.62_wp))
   end function naf_tip

end module thermal_support

!> A one-dimensional periodic landscape given by its Fourier series along the
!> lattice x axis, flat across:
!>   V(x) = -Σ_n [c_n cos(n q x) + s_n sin(n q x)],   q = 2π/a,  n = 1..N,
!> with c_n, s_n in eV.  One term c_1 = V0 is the row -V0 cos(2πx/a)
!> (friction_surface_row), evaluated with the same operations in the same
!> order, so the two agree bit for bit; more terms give barrier shapes other
!> than the sinusoid's.
!>
!> The barrier's shape near the critical point (fold_shape): a tip on a
!> spring k along x over V follows a minimum of E(x; X) = V(x) + k/2 (x - X)²
!> until that minimum merges with the saddle ahead, at a fold x_c where
!> V''(x_c) = -k.  Close to it the barrier is cubic whatever V is,
!>   ΔE = (4/3) (k δX)^(3/2) / sqrt(σ),   σ = |V'''(x_c)|/2,  δX = X_c - X,
!> and the mean friction (the dissipated energy per distance) falls linearly
!> with δX: F_c - F = k Δx δX / L (Δx the jump from the fold to where the
!> tip lands, L the support travel between two folds).  So
!>   ΔE = μ (F_c - F)^(3/2),   μ = (4/3) σ^(-1/2) (L/Δx)^(3/2),
!> and Sang, Dubé and Grant's law F = F_c - (β k_B T ln(v_c/v))^(2/3) has
!> β = 1/μ.  For the sinusoid with a soft spring (the fold at the
!> inflection, Δx = L = a) β = 3π sqrt(F_c)/(2 sqrt(2) a), their value.
module friction_surface_fourier
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use friction_kinds, only: wp, pi
   use friction_strings, only: itoa
   use friction_surface_potential, only: surface_potential, spice_form
   implicit none
   private

   public :: fourier_potential, new_fourier_potential, fold_shape, barrier_shape, max_harmonics

   !> The most harmonics a landscape may have (&fourier cosine(1:16), sine(1:16)).
   integer, parameter :: max_harmonics = 16

   type, extends(surface_potential) :: fourier_potential
      real(wp), allocatable :: c(:)   !! cosine coefficients c_n, eV
      real(wp), allocatable :: s(:)   !! sine coefficients s_n, eV
      real(wp) :: q = 0.0_wp          !! wave number 2π/a, 1/Å
   contains
      procedure :: energy
      procedure :: gradient
      procedure :: hessian
      procedure :: dimensions
      procedure :: spice
      procedure :: derivatives
   end type fourier_potential

   !> The fold of a tip on a spring moving one way over a 1-D landscape, in
   !> internal units (eV, Å); NaN where there is none (`why` says why).
   type :: barrier_shape
      real(wp) :: fold = 0.0_wp        !! x_c: the tip where its minimum vanishes, Å (mod a)
      real(wp) :: support = 0.0_wp     !! X_c: the support there, Å
      real(wp) :: third = 0.0_wp       !! V'''(x_c), eV/Å³
      real(wp) :: jump = 0.0_wp        !! Δx: from the fold to the landing minimum, Å
      real(wp) :: travel = 0.0_wp      !! L: support travel between two folds, Å
      real(wp) :: dissipated = 0.0_wp  !! energy lost in the jump, eV
      real(wp) :: exponent = 0.0_wp    !! of ΔE ∝ (F_c - F)^exponent: 3/2 at a fold
      real(wp) :: prefactor = 0.0_wp   !! μ of ΔE = μ (F_c - F)^(3/2), eV/(eV/Å)^(3/2)
      integer :: folds = 0             !! folds per cycle of the motion (1: Sang's law applies)
      character(len=:), allocatable :: why  !! '' when the shape is defined
   end type barrier_shape

contains

   !> The landscape with cosine and sine coefficients (eV, harmonics 1 to
   !> size(c); size(s) = size(c)) and period a (Å) along x.
   pure function new_fourier_potential(c, s, a) result(self)
      real(wp), intent(in) :: c(:), s(:), a
      type(fourier_potential) :: self

      self%c = c
      self%s = s
      self%q = 2.0_wp * pi / a
   end function new_fourier_potential

   pure function energy(self, r) result(v)
      class(fourier_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp) :: v
      real(wp) :: kn
      integer :: n

      v = 0.0_wp
      do n = 1, size(self%c)
         kn = real(n, wp) * self%q
         v = v - self%c(n) * cos(kn * r(1)) - self%s(n) * sin(kn * r(1))
      end do
   end function energy

   pure subroutine gradient(self, r, g)
      class(fourier_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: g(3)
      real(wp) :: kn
      integer :: n

      g = 0.0_wp
      do n = 1, size(self%c)
         kn = real(n, wp) * self%q
         g(1) = g(1) + self%c(n) * kn * sin(kn * r(1)) - self%s(n) * kn * cos(kn * r(1))
      end do
   end subroutine gradient

   pure subroutine hessian(self, r, h)
      class(fourier_potential), intent(in) :: self
      real(wp), intent(in) :: r(3)
      real(wp), intent(out) :: h(3, 3)
      real(wp) :: kn
      integer :: n

      h = 0.0_wp
      do n = 1, size(self%c)
         kn = real(n, wp) * self%q
         h(1, 1) = h(1, 1) + self%c(n) * kn**2 * cos(kn * r(1)) + self%s(n) * kn**2 * sin(kn * r(1))
      end do
   end subroutine hessian

   pure function dimensions(self) result(n)
      class(fourier_potential), intent(in) :: self
      integer :: n

      n = 2
   end function dimensions

   !> V and its first three derivatives along x at x, eV and eV/Å^k.
   pure function derivatives(self, x) result(d)
      class(fourier_potential), intent(in) :: self
      real(wp), intent(in) :: x
      real(wp) :: d(0:3)
      real(wp) :: kn, cn, sn
      integer :: n

      d = 0.0_wp
      do n = 1, size(self%c)
         kn = real(n, wp) * self%q
         cn = cos(kn * x)
         sn = sin(kn * x)
         d(0) = d(0) - self%c(n) * cn - self%s(n) * sn
         d(1) = d(1) + kn * (self%c(n) * sn - self%s(n) * cn)
         d(2) = d(2) + kn**2 * (self%c(n) * cn + self%s(n) * sn)
         d(3) = d(3) + kn**3 * (self%s(n) * cn - self%c(n) * sn)
      end do
   end function derivatives

   !> The series, flat across: no force in y.
   pure subroutine spice(self, form)
      class(fourier_potential), intent(in) :: self
      type(spice_form), intent(out) :: form
      character(len=:), allocatable :: terms, n
      integer :: k

      form%comment = [character(len=100) :: 'Surface: a one-dimensional Fourier series along x, flat across,', &
         & 'V = -sum_n [cn cos(n qx x) + sn sin(n qx x)], qx = 2 pi/ax.']
      form%names = [character(len=8) :: 'qx']
      form%values = [self%q]
      terms = ''
      do k = 1, size(self%c)
         n = itoa(k)
         form%names = [character(len=8) :: form%names, 'c'//n, 's'//n]
         form%values = [form%values, self%c(k), self%s(k)]
         if (k > 1) terms = terms//'+'
         terms = terms//'c'//n//'*'//n//'*qx*sin('//n//'*qx*V(xt))-s'//n//'*'//n//'*qx*cos('//n//'*qx*V(xt))'
      end do
      ! (In parentheses: the netlist subtracts it from the spring's force.)
      form%gradient_x = '('//terms//')'
      form%gradient_y = '0'
      form%why = ''
   end subroutine spice

   !> The fold met by a tip on a spring k (eV/Å²) along x whose support moves
   !> in +x (direction > 0) or -x, in the slow limit (the tip in its
   !> minimum until the minimum vanishes), once the motion repeats: where
   !> the minimum vanishes, V''' there, the jump, the support travel per
   !> cycle and the energy each jump dissipates; with one fold per cycle the
   !> barrier's exponent 3/2 and prefactor μ of ΔE = μ (F_c - F)^(3/2), F
   !> the mean force along x (see the module's comment).  NaN and a reason
   !> when the spring is too stiff for stick-slip, or for μ when there are
   !> several folds per cycle or V''' vanishes at the fold.
   pure function fold_shape(potential, k, direction) result(shape)
      type(fourier_potential), intent(in) :: potential
      real(wp), intent(in) :: k
      integer, intent(in) :: direction
      type(barrier_shape) :: shape
      type(fourier_potential) :: w
      real(wp), allocatable :: candidates(:)
      real(wp) :: a, h, x, g_c, x_land, first, dissipated, nan, third
      real(wp) :: folds(64), jumps(64), thirds(64), lost(64), d0(0:3), d1(0:3)
      integer :: m, i, j, steps, count, found

      nan = ieee_value(0.0_wp, ieee_quiet_nan)
      shape%fold = nan
      shape%support = nan
      shape%third = nan
      shape%jump = nan
      shape%travel = nan
      shape%dissipated = nan
      shape%exponent = nan
      shape%prefactor = nan
      shape%why = ''
      ! Against the support's motion in -x, the mirror image x -> -x moving in +x.
      w = potential
      if (direction < 0) w%s = -w%s
      a = 2.0_wp * pi / w%q
      ! The folds are the maxima of g(x) = V'(x) + k x, where V'' = -k and V''' < 0.
      m = 64 * size(w%c)
      h = a / real(m, wp)
      allocate (candidates(0))
      do i = 0, m - 1
         if (curvature_gap(w, k, i * h) > 0.0_wp .and. curvature_gap(w, k, (i + 1) * h) <= 0.0_wp) &
            & candidates = [candidates, root_of_gap(w, k, i * h, (i + 1) * h)]
      end do
      if (size(candidates) == 0) then
         shape%why = 'no stick-slip: the spring is stiffer than the landscape''s most negative curvature'
         return
      end if
      ! Follow the motion: from a fold, land where g first comes back up to
      ! g(x_c); from there the minimum is followed to the next maximum of g.
      x = candidates(1)
      count = 0
      found = 0
      first = 0.0_wp
      do i = 1, size(folds)
         g_c = g_of(w, k, x)
         x_land = x
         steps = 0
         do
            steps = steps + 1
            x_land = x_land + h
            if (g_of(w, k, x_land) >= g_c .or. steps > 64 * m) exit
         end do
         if (steps > 64 * m) then
            shape%why = 'no landing minimum found within 64 periods of the fold'
            return
         end if
         x_land = root_of_level(w, k, g_c, x_land - h, x_land)
         d0 = w%derivatives(x)
         d1 = w%derivatives(x_land)
         folds(i) = x
         jumps(i) = x_land - x
         thirds(i) = d0(3)
         lost(i) = d0(0) - d1(0) + 0.5_wp * k * (g_c / k - x)**2 - 0.5_wp * k * (g_c / k - x_land)**2
         ! The next fold: the first candidate past the landing.
         x = next_candidate(candidates, a, x_land)
         ! A cycle: a fold met again, a whole number of periods on.
         do j = 1, i
            if (abs(modulo(folds(j) - x + 0.5_wp * a, a) - 0.5_wp * a) <= 1.0e-9_wp * a) then
               found = j
               exit
            end if
         end do
         if (found > 0) then
            count = i - found + 1
            first = folds(found)
            exit
         end if
      end do
      if (found == 0) then
         shape%why = 'the motion did not repeat within 64 folds'
         return
      end if
      shape%folds = count
      shape%fold = modulo(first, a)
      if (direction < 0) shape%fold = modulo(-first, a)
      shape%travel = x - first
      dissipated = sum(lost(found:found + count - 1))
      shape%dissipated = dissipated
      third = thirds(found)
      shape%third = merge(-third, third, direction < 0)
      shape%jump = jumps(found)
      shape%support = (g_of(w, k, first) / k) * real(sign(1, direction), wp)
      if (count /= 1) then
         shape%why = itoa(count)//' jumps per cycle of the motion: a single barrier''s law does not apply'
         return
      end if
      if (.not. (abs(third) > 0.0_wp)) then
         shape%why = 'V''''''(x_c) = 0 at the fold: the barrier is not cubic there'
         return
      end if
      shape%exponent = 1.5_wp
      shape%prefactor = 4.0_wp / 3.0_wp / sqrt(0.5_wp * abs(third)) * (shape%travel / shape%jump)**1.5_wp
   end function fold_shape

   !> V''(x) + k.
   pure real(wp) function curvature_gap(w, k, x)
      type(fourier_potential), intent(in) :: w
      real(wp), intent(in) :: k, x
      real(wp) :: d(0:3)

      d = w%derivatives(x)
      curvature_gap = d(2) + k
   end function curvature_gap

   !> g(x) = V'(x) + k x = k X at a stationary point.
   pure real(wp) function g_of(w, k, x)
      type(fourier_potential), intent(in) :: w
      real(wp), intent(in) :: k, x
      real(wp) :: d(0:3)

      d = w%derivatives(x)
      g_of = d(1) + k * x
   end function g_of

   !> The root of V'' + k in [lo, hi] (positive at lo, not at hi), by bisection to rounding.
   pure real(wp) function root_of_gap(w, k, lo, hi) result(x)
      type(fourier_potential), intent(in) :: w
      real(wp), intent(in) :: k, lo, hi
      real(wp) :: l, u
      integer :: i

      l = lo
      u = hi
      do i = 1, 200
         x = 0.5_wp * (l + u)
         if (x <= l .or. x >= u) exit
         if (curvature_gap(w, k, x) > 0.0_wp) then
            l = x
         else
            u = x
         end if
      end do
      x = 0.5_wp * (l + u)
   end function root_of_gap

   !> Where g rises through the level in [lo, hi] (below at lo, not at hi).
   pure real(wp) function root_of_level(w, k, level, lo, hi) result(x)
      type(fourier_potential), intent(in) :: w
      real(wp), intent(in) :: k, level, lo, hi
      real(wp) :: l, u
      integer :: i

      l = lo
      u = hi
      do i = 1, 200
         x = 0.5_wp * (l + u)
         if (x <= l .or. x >= u) exit
         if (g_of(w, k, x) < level) then
            l = x
         else
            u = x
         end if
      end do
      x = 0.5_wp * (l + u)
   end function root_of_level

   !> The first fold candidate (periodic with a) past x.
   pure real(wp) function next_candidate(candidates, a, x) result(next)
      real(wp), intent(in) :: candidates(:), a, x
      real(wp) :: base, trial
      integer :: i

      base = a * floor(x / a)
      next = huge(1.0_wp)
      do i = 1, size(candidates)
         trial = base + modulo(candidates(i), a)
         if (trial <= x) trial = trial + a
         next = min(next, trial)
      end do
   end function next_candidate

end module friction_surface_fourier

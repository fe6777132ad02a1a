!> Parameters of the Girling duo-servo brake (paper §4, Eq. 10) and their
!> derivation from the dimensional data of §6.2.
!>
!> The brake is integrated in the nondimensional form of Eq. 10: time
!> τ = t √(k1/m), lengths x, y in metres (the paper keeps them dimensional:
!> g' and v'_dr are in m), velocities in metres per unit τ:
!>
!>   x'' + 2x - y = -μ N' (2/π) arctan(ε' v_rel) / (1 + δ' |v_rel|)
!>   ξ y'' - x + κ y = 0,      N' = (1 - κ) y + g',   v_rel = x' - v'_dr.
!>
!> Dimensional data convert at the boundary: ξ = J/(m L²) with J = m_c L²/3,
!> κ = (k1 + k3)/k1, g' = g (m + m_c)/k1 (the normal reaction carries both
!> weights, Eq. 8), and since v' = v √(m/k1): ε' = ε √(k1/m),
!> δ' = δ √(k1/m), v'_dr = v_dr √(m/k1).  Eq. 10 assumes k2 = k1 (§4.1).
module friction_brake_params
   use friction_kinds, only: wp, pi
   use friction_error, only: error_type, fatal_error, error_input
   use friction_strings, only: rtoa
   implicit none
   private

   public :: brake_parameters, brake_dimensional, derive_parameters, time_scale

   !> The nondimensional parameters of Eq. 10 (defaults: the paper's §6.2).
   type :: brake_parameters
      real(wp) :: xi = 0.412_wp              !! ξ = J/(m L²), crank inertia over block inertia
      real(wp) :: kappa = 1.5_wp             !! κ = (k1 + k3)/k1
      real(wp) :: g_prime = 0.01778_wp       !! g' = g (m + m_c)/k1, m
      real(wp) :: mu = 0.59_wp               !! kinetic friction coefficient μ
      real(wp) :: mu_s = 0.59_wp             !! static friction coefficient μs
      real(wp) :: epsilon_prime = 3.5121e7_wp  !! ε', steepness of the arctan law (per m per unit τ)
      real(wp) :: delta_prime = 3.5121_wp    !! δ', velocity weakening (per m per unit τ)
      real(wp) :: v_dr = -0.002788_wp        !! v'_dr, belt velocity, m per unit τ
   contains
      procedure :: normal_force
      procedure :: elastic_force
      procedure :: natural_frequencies
   end type brake_parameters

   !> The dimensional data of §6.2 (SI units).
   type :: brake_dimensional
      real(wp) :: arm_length = 0.105_wp   !! crank arm L, m (cancels from ξ with J = m_c L²/3)
      real(wp) :: drum_radius = 0.11_wp   !! drum radius R, m (recorded; not in Eq. 10)
      real(wp) :: crank_mass = 0.215_wp   !! m_c, kg
      real(wp) :: block_mass = 0.174_wp   !! m, kg
      real(wp) :: k1 = 214.62_wp          !! block to chassis, N/m
      real(wp) :: k2 = 214.62_wp          !! block to crank, horizontal, N/m (Eq. 10: = k1)
      real(wp) :: k3 = 107.31_wp          !! block to crank, vertical, N/m
      real(wp) :: gravity = 9.81_wp       !! g, m/s²
      real(wp) :: epsilon = 1.0e6_wp      !! ε, s/m (ε' = 3.5121e7 of §6.2 is 1.0000e6 s/m)
      real(wp) :: delta = 0.1_wp          !! δ, s/m (δ' = 3.5121 of §6.2)
      real(wp) :: v_dr = -0.097916_wp     !! belt velocity, m/s (v'_dr = -0.002788 of §6.2)
   end type brake_dimensional

contains

   !> N' = (1 - κ) y + g': the normal reaction over k1 (m).
   pure real(wp) function normal_force(self, y)
      class(brake_parameters), intent(in) :: self
      real(wp), intent(in) :: y

      normal_force = (1.0_wp - self%kappa) * y + self%g_prime
   end function normal_force

   !> 2x - y: the pull of the springs k1 and k2 on the block, over k1 (m).
   !> Stick holds while |2x - y| <= μs N' (Eq. 5).
   pure real(wp) function elastic_force(self, x, y)
      class(brake_parameters), intent(in) :: self
      real(wp), intent(in) :: x, y

      elastic_force = 2.0_wp * x - y
   end function elastic_force

   !> Natural frequencies of the linear part (μ = 0) in cycles per unit τ,
   !> lower first: det(K - ω² M) = 0 with M = diag(1, ξ), K = [2 -1; -1 κ]
   !> gives ξ ω⁴ - (κ + 2ξ) ω² + 2κ - 1 = 0.
   pure function natural_frequencies(self) result(f)
      class(brake_parameters), intent(in) :: self
      real(wp) :: f(2)
      real(wp) :: b, c, root, w2(2)

      b = (self%kappa + 2.0_wp * self%xi) / self%xi
      c = (2.0_wp * self%kappa - 1.0_wp) / self%xi
      root = sqrt(max(0.0_wp, b * b - 4.0_wp * c))
      ! The smaller root without cancellation: w2(1) w2(2) = c.
      w2(2) = 0.5_wp * (b + root)
      w2(1) = c / w2(2)
      f = sqrt(max(0.0_wp, w2)) / (2.0_wp * pi)
   end function natural_frequencies

   !> √(m/k1): seconds per unit τ.
   pure real(wp) function time_scale(dim)
      type(brake_dimensional), intent(in) :: dim

      time_scale = sqrt(dim%block_mass / dim%k1)
   end function time_scale

   !> The parameters of Eq. 10 from the dimensional data; μ and μs are
   !> dimensionless either way.  Rejects data Eq. 10 cannot represent.
   subroutine derive_parameters(dim, mu, mu_s, params, error)
      type(brake_dimensional), intent(in) :: dim
      real(wp), intent(in) :: mu, mu_s
      type(brake_parameters), intent(out) :: params
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: scale, inertia

      if (.not. (dim%block_mass > 0.0_wp .and. dim%k1 > 0.0_wp .and. dim%arm_length > 0.0_wp)) then
         call fatal_error(error, 'block_mass, k1 and arm_length must be > 0', error_input)
         return
      end if
      if (abs(dim%k2 - dim%k1) > 1.0e-9_wp * dim%k1) then
         call fatal_error(error, 'k2 = '//rtoa(dim%k2)//' differs from k1 = '//rtoa(dim%k1) &
            & //': Eq. 10 assumes k2 = k1 (paper §4.1)', error_input)
         return
      end if
      scale = time_scale(dim)
      inertia = dim%crank_mass * dim%arm_length**2 / 3.0_wp   ! J = m_c L²/3 (§6.2)
      params%xi = inertia / (dim%block_mass * dim%arm_length**2)
      params%kappa = (dim%k1 + dim%k3) / dim%k1
      params%g_prime = dim%gravity * (dim%block_mass + dim%crank_mass) / dim%k1
      params%mu = mu
      params%mu_s = mu_s
      params%epsilon_prime = dim%epsilon / scale
      params%delta_prime = dim%delta / scale
      params%v_dr = dim%v_dr * scale
   end subroutine derive_parameters

end module friction_brake_params

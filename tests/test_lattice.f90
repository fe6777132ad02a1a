!> The Lennard-Jones lattice sum (Eq. 3) and its crystal nets: the pair
!> potential's minimum, analytic derivatives against finite differences,
!> generated graphite against its geometry, XYZ round trip and errors, the
!> cutoff error against the full sum, and the locality of a vacancy.
program test_lattice
   use friction_kinds, only: wp, pi, ev_per_angstrom_to_nn
   use friction_error, only: error_type
   use friction_surface_net, only: crystal_net, graphite_net, square_net, read_xyz, write_xyz
   use friction_surface_lennard_jones, only: lj_potential, new_lj_potential, lj_pair_energy, &
      & cutoff_for_tolerance
   use friction_surface_potential, only: surface_potential
   use friction_afm_config, only: afm_config, new_potential
   use friction_afm_scan, only: afm_scanner, trip_record, q_fx, q_fy, q_fz, n_quantities
   use testing, only: test_suite, check, check_close
   implicit none

   real(wp), parameter :: a = 2.46_wp, eps = 0.87381e-2_wp, sigma = 2.4945_wp
   type(test_suite) :: suite

   suite%name = 'lattice'
   call suite%add('pair_minimum', pair_minimum)
   call suite%add('sum_derivatives', sum_derivatives)
   call suite%add('graphite_geometry', graphite_geometry)
   call suite%add('square_geometry', square_geometry)
   call suite%add('xyz_round_trip', xyz_round_trip)
   call suite%add('xyz_errors', xyz_errors)
   call suite%add('cutoff_error', cutoff_error)
   call suite%add('vacancy_is_local', vacancy_is_local)
   ! Random test points, the same on every run.
   call random_init(repeatable=.true., image_distinct=.false.)
   call suite%run_all()

contains

   !> A single atom: the minimum of 4ε[(σ/r)^12 - (σ/r)^6] is at 2^(1/6) σ
   !> with depth ε (calculus); the summed potential of a one-atom net has zero
   !> gradient there and is higher on either side.
   subroutine pair_minimum(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(crystal_net) :: net
      type(lj_potential) :: p
      real(wp) :: rmin, g(3)

      net%position = reshape([0.0_wp, 0.0_wp, 0.0_wp], [3, 1])
      net%species = [1]
      p = new_lj_potential(net, [eps], [sigma], 0.0_wp)
      rmin = 2.0_wp**(1.0_wp / 6.0_wp) * sigma
      call check_close(failure, lj_pair_energy(eps, sigma, rmin), -eps, 1.0e-15_wp, 'pair depth')
      call check_close(failure, p%energy([0.0_wp, 0.0_wp, rmin]), -eps, 1.0e-15_wp, 'summed depth')
      call p%gradient([0.3_wp * rmin, 0.0_wp, sqrt(0.91_wp) * rmin], g)
      call check(failure, maxval(abs(g)) < 1.0e-14_wp, 'gradient not zero at the minimum distance')
      call check(failure, p%energy([0.0_wp, 0.0_wp, 0.99_wp * rmin]) > -eps, 'not a minimum (inside)')
      call check(failure, p%energy([0.0_wp, 0.0_wp, 1.01_wp * rmin]) > -eps, 'not a minimum (outside)')
      ! σ is where the pair energy crosses zero.
      call check_close(failure, lj_pair_energy(eps, sigma, sigma), 0.0_wp, 1.0e-17_wp, 'V(σ) = 0')
   end subroutine pair_minimum

   !> Gradient and Hessian of the sum against fourth-order centred
   !> differences (h = 1e-3 Å: truncation ~ h⁴ V⁽⁵⁾/30, below 1e-9 of the
   !> pair terms even at 2 Å where the repulsion is steep and the terms of
   !> neighbouring atoms cancel; round-off ~ 1e-16 V/h ≈ 1e-13) at random tip
   !> positions 2 to 5 Å above a flake, for the
   !> full sum and for a cut sum; tolerance 1e-6 relative to the largest
   !> component (or ε/σ where the gradient nearly vanishes).  The cut sum
   !> jumps where an atom crosses the cutoff sphere, so positions with an
   !> atom within 3h of it are skipped.
   subroutine sum_derivatives(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(lj_potential) :: p
      type(crystal_net) :: net
      real(wp), parameter :: h = 1.0e-3_wp
      real(wp) :: r(3), e(3), g(3), gp(3), gm(3), gp2(3), gm2(3), hess(3, 3), fd(3), scale, rc
      real(wp) :: distance(6 * 4**2)
      integer :: trial, i, variant, tested
      character(len=64) :: what

      net = graphite_net(a, 3)
      do variant = 1, 2
         rc = merge(0.0_wp, 7.0_wp, variant == 1)
         p = new_lj_potential(net, [eps], [sigma], rc)
         tested = 0
         do trial = 1, 200
            call random_number(r)
            r = [(r(1) - 0.5_wp) * 8.0_wp, (r(2) - 0.5_wp) * 8.0_wp, 2.0_wp + 3.0_wp * r(3)]
            distance = norm2(net%position - spread(r, 2, net%size()), dim=1)
            if (rc > 0.0_wp .and. any(abs(distance - rc) < 3 * h)) cycle   ! the stencil reaches 2h
            tested = tested + 1
            call p%gradient(r, g)
            call p%hessian(r, hess)
            scale = max(maxval(abs(g)), eps / sigma)
            do i = 1, 3
               e = 0.0_wp
               e(i) = h
               write (what, '(a, i0, a, i0, a, i0)') 'dV/dr', i, ' trial ', trial, ' variant ', variant
               call check_close(failure, g(i), (8 * (p%energy(r + e) - p%energy(r - e)) &
                  & - (p%energy(r + 2 * e) - p%energy(r - 2 * e))) / (12 * h), 1.0e-6_wp * scale, trim(what))
               call p%gradient(r + e, gp)
               call p%gradient(r - e, gm)
               call p%gradient(r + 2 * e, gp2)
               call p%gradient(r - 2 * e, gm2)
               fd = (8 * (gp - gm) - (gp2 - gm2)) / (12 * h)
               write (what, '(a, i0, a, i0, a, i0)') 'Hessian column ', i, ' trial ', trial, ' variant ', variant
               call check(failure, maxval(abs(hess(:, i) - fd)) <= 1.0e-6_wp * max(maxval(abs(hess)), &
                  & eps / sigma**2), trim(what))
            end do
         end do
         call check(failure, tested > 150, 'too few positions away from the cutoff sphere')
      end do
   end subroutine sum_derivatives

   !> Shells n give 1 + 3n(n+1) hexagons and 6(n+1)² atoms: 6 (benzene), 24
   !> (coronene), 600 for the paper's 271 hexagons.  Every atom's nearest
   !> neighbours sit at the C–C distance a/√3, two or three of them.
   subroutine graphite_geometry(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(crystal_net) :: net
      integer :: n, i, j, close_ones
      real(wp) :: d, nearest

      net = graphite_net(a, 0)
      call check(failure, net%size() == 6, 'shells = 0 is not benzene')
      net = graphite_net(a, 1)
      call check(failure, net%size() == 24, 'shells = 1 is not coronene')
      net = graphite_net(a, 9)
      n = net%size()
      call check(failure, n == 600, 'shells = 9 does not give 600 atoms')
      do i = 1, n
         nearest = huge(1.0_wp)
         close_ones = 0
         do j = 1, n
            if (j == i) cycle
            d = norm2(net%position(:, j) - net%position(:, i))
            nearest = min(nearest, d)
            if (abs(d - a / sqrt(3.0_wp)) < 1.0e-9_wp) close_ones = close_ones + 1
         end do
         call check_close(failure, nearest, a / sqrt(3.0_wp), 1.0e-12_wp, 'nearest-neighbour distance')
         call check(failure, close_ones == 2 .or. close_ones == 3, 'an atom without 2 or 3 bonds')
      end do
      ! Centred on the origin: the central hexagon surrounds (0, 0).
      call check_close(failure, norm2(sum(net%position, dim=2) / n), 0.0_wp, 1.0e-12_wp, 'flake centre')
   end subroutine graphite_geometry

   subroutine square_geometry(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(crystal_net) :: net

      net = square_net(3.0_wp, 4)
      call check(failure, net%size() == 16, 'square net of side 4 has not 16 atoms')
      call check_close(failure, norm2(net%position(:, 2) - net%position(:, 1)), 3.0_wp, 1.0e-14_wp, 'spacing')
      call check_close(failure, norm2(sum(net%position, dim=2)), 0.0_wp, 1.0e-12_wp, 'centred')
   end subroutine square_geometry

   !> Written to 1e-10 Å and read back: the same atoms in the same order.
   subroutine xyz_round_trip(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(crystal_net) :: net, back
      type(error_type), allocatable :: error
      character(len=*), parameter :: path = 'lattice_round_trip.xyz'

      net = graphite_net(a, 2)
      call net%substitute([5, 17], 2)
      call write_xyz(path, net, [character(len=2) :: 'C', 'N'], 'round trip', error)
      if (.not. allocated(error)) call read_xyz(path, [character(len=2) :: 'C', 'N'], back, error)
      if (allocated(error)) then
         failure = error%message
         return
      end if
      call check(failure, back%size() == net%size(), 'atom count changed')
      if (allocated(failure)) return
      call check(failure, maxval(abs(back%position - net%position)) < 1.0e-9_wp, 'positions changed')
      call check(failure, all(back%species == net%species), 'species changed')
      call check(failure, count(back%species == 2) == 2, 'substitutions lost')
   end subroutine xyz_round_trip

   !> Malformed files name the file and the line.
   subroutine xyz_errors(failure)
      character(len=:), allocatable, intent(out) :: failure

      call expect_error(failure, '3'//new_line('a')//'x'//new_line('a')//'C 0 0 0'//new_line('a') &
         & //'C 1 0 0'//new_line('a'), 'bad_count.xyz:5', 'ends after 2 atoms')
      call expect_error(failure, '2'//new_line('a')//'x'//new_line('a')//'C 0 0 0'//new_line('a') &
         & //'C 1 zero 0'//new_line('a'), 'bad_count.xyz:4', 'numbers')
      call expect_error(failure, '2'//new_line('a')//'x'//new_line('a')//'C 0 0 0'//new_line('a') &
         & //'Si 1 0 0'//new_line('a'), 'bad_count.xyz:4', "unknown species 'Si'")
      call expect_error(failure, '1'//new_line('a')//'x'//new_line('a')//'C 0 0 0'//new_line('a') &
         & //'C 1 0 0'//new_line('a'), 'bad_count.xyz:4', 'more atoms')
      call expect_error(failure, 'many'//new_line('a'), 'bad_count.xyz:1', 'number of atoms')
   end subroutine xyz_errors

   subroutine expect_error(failure, text, where, what)
      character(len=:), allocatable, intent(inout) :: failure
      character(len=*), intent(in) :: text, where, what
      type(crystal_net) :: net
      type(error_type), allocatable :: error
      integer :: unit

      open (newunit=unit, file='bad_count.xyz', status='replace', action='write', access='stream', &
         & form='unformatted')
      write (unit) text
      close (unit)
      call read_xyz('bad_count.xyz', [character(len=1) :: 'C'], net, error)
      call check(failure, allocated(error), 'accepted a malformed file: '//what)
      if (allocated(failure)) return
      call check(failure, index(error%message, where) > 0 .and. index(error%message, what) > 0, &
         & 'message "'//error%message//'" lacks "'//where//'" or "'//what//'"')
   end subroutine expect_error

   !> The cutoff chosen for a force tolerance keeps the cut sum within that
   !> tolerance of the full sum, at random tip positions over the middle of
   !> a flake large enough (2646 atoms, radius ~ 50 Å) that atoms lie beyond
   !> the cutoff in every direction.
   subroutine cutoff_error(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(crystal_net) :: net
      type(lj_potential) :: cut, full
      real(wp) :: tolerance, rc, r(3), gc(3), gf(3), worst
      integer :: trial

      net = graphite_net(a, 20)
      tolerance = 1.0e-4_wp / ev_per_angstrom_to_nn     ! 1e-4 nN in eV/Å
      ! Graphite: 2 atoms per cell of a²√3/2.
      rc = cutoff_for_tolerance(eps, sigma, 4.0_wp / (sqrt(3.0_wp) * a**2), tolerance)
      cut = new_lj_potential(net, [eps], [sigma], rc)
      full = new_lj_potential(net, [eps], [sigma], 0.0_wp)
      worst = 0.0_wp
      do trial = 1, 200
         call random_number(r)
         r = [(r(1) - 0.5_wp) * 10.0_wp, (r(2) - 0.5_wp) * 10.0_wp, 2.0_wp + 4.0_wp * r(3)]
         call cut%gradient(r, gc)
         call full%gradient(r, gf)
         worst = max(worst, norm2(gc - gf))
      end do
      call check(failure, rc > 2 * sigma .and. rc < 30.0_wp, 'implausible cutoff')
      call check_close(failure, worst, 0.0_wp, tolerance, 'largest force error of the cut sum, eV/Å')
      ! And the bound is not vacuous: a cutoff of 2σ misses more than the tolerance.
      cut = new_lj_potential(net, [eps], [sigma], 2 * sigma)
      call cut%gradient([0.0_wp, 0.0_wp, 3.0_wp], gc)
      call full%gradient([0.0_wp, 0.0_wp, 3.0_wp], gf)
      call check(failure, norm2(gc - gf) > tolerance, 'a short cutoff should miss more than the tolerance')
   end subroutine cutoff_error

   !> Two scan lines over a flake with and without a vacancy under the second
   !> line: the first line, which never comes within the cutoff of the
   !> vacancy, is the same to rounding; the second is not.
   subroutine vacancy_is_local(failure)
      character(len=:), allocatable, intent(out) :: failure
      type(afm_config) :: c
      real(wp), allocatable :: perfect(:, :, :), defect(:, :, :)
      real(wp) :: near, far
      integer :: site

      c%potential = 'lj'
      c%net = 'graphite'
      c%shells = 6
      c%cutoff = 6.0_wp
      c%mass = 1.0e-6_wp
      c%kx = 2.5_wp
      c%ky = 2.5_wp
      c%kz = 0.25_wp
      c%cx = 0.0_wp
      c%cy = 0.0_wp
      c%support_z = -1.0_wp
      c%velocity = 100.0_wp
      c%length = 3.0_wp
      ! The first line (where the contact height is set) runs 9 Å from the
      ! vacancy, more than the cutoff; the second passes over it.
      c%width = 9.0_wp
      c%origin_x = -1.5_wp
      c%origin_y = -9.0_wp
      c%nx = 16
      c%ny = 2
      c%solver%rtol = 1.0e-8_wp
      c%solver%atol = 1.0e-8_wp
      call scan_map(c, perfect, failure)
      if (allocated(failure)) return
      ! The atom nearest to the middle of the first line.
      site = nearest_site(c, [0.0_wp, 0.0_wp])   ! under the middle of the second line
      c%vacancies(1) = site
      call scan_map(c, defect, failure)
      if (allocated(failure)) return
      far = maxval(abs(defect(:, 1, [q_fx, q_fy, q_fz]) - perfect(:, 1, [q_fx, q_fy, q_fz])))
      near = maxval(abs(defect(:, 2, [q_fx, q_fy, q_fz]) - perfect(:, 2, [q_fx, q_fy, q_fz])))
      call check(failure, near > 1.0e-3_wp, 'the vacancy does not change the line over it')
      call check_close(failure, far, 0.0_wp, 1.0e-12_wp, 'the line far from the vacancy changed, nN')
   end subroutine vacancy_is_local

   integer function nearest_site(c, at)
      type(afm_config), intent(in) :: c
      real(wp), intent(in) :: at(2)
      type(crystal_net) :: net
      integer :: i

      net = graphite_net(c%a, c%shells)
      nearest_site = 1
      do i = 2, net%size()
         if (norm2(net%position(1:2, i) - at) < norm2(net%position(1:2, nearest_site) - at)) nearest_site = i
      end do
   end function nearest_site

   subroutine scan_map(c, values, failure)
      type(afm_config), intent(in) :: c
      real(wp), allocatable, intent(out) :: values(:, :, :)
      character(len=:), allocatable, intent(inout) :: failure
      class(surface_potential), allocatable :: potential
      type(afm_scanner), target :: scanner
      type(trip_record) :: trip
      type(error_type), allocatable :: error
      integer :: j

      call new_potential(c, potential, error)
      if (.not. allocated(error)) call scanner%init(c, potential, error)
      allocate (values(c%nx, c%ny, n_quantities))
      do j = 1, c%ny
         if (.not. allocated(error)) call scanner%run_trip(j - 1, .true., trip, error)
         if (.not. allocated(error)) values(:, j, :) = trip%values
      end do
      if (allocated(error)) failure = error%message
   end subroutine scan_map

end program test_lattice

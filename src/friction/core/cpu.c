/* Whether the surface table's kernels compiled for AVX2 (x86-64-v3,
 * table_kernels_wide.F90) can run on this processor: the build compiled
 * them so (FRICTION_WIDE_KERNELS, CMakeLists.txt) and the processor and
 * the operating system support every instruction of that level.  The
 * answer is the processor's, the same at every call. */
int friction_wide_kernels(void)
{
#if defined(FRICTION_WIDE_KERNELS) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") != 0;
#else
  return 0;
#endif
}

/* A user of the installed C API: the version and one NaF scan line. */
#include <friction.h>

#include <stdio.h>

int main(void) {
  char version[32], message[256];
  double fx[8], fy[8];
  friction_error *err = friction_error_new();
  if (friction_version(version, sizeof version) != FRICTION_OK) return 1;
  int status = friction_afm_line("naf", 1.0, 4.62, 4.62, 2.46, 1.0e-8, 10.0, 10.0, 1.0e-3, 1.0e-3,
                                 400.0, 0.0, 0.0, 0.0, 4.62, 8, 1, "rkf45", 1.0e-3, 1.0e-4, fx, fy, err);
  if (status != FRICTION_OK) {
    friction_error_message(err, message, sizeof message);
    fprintf(stderr, "consumer: %s\n", message);
    return 1;
  }
  friction_error_free(err);
  printf("friction %s: fx[1] = %.6f nN\n", version, fx[1]);
  return fx[1] != 0.0 ? 0 : 1;
}

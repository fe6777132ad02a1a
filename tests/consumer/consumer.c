/* A user of the installed C API: the versions, a configuration and one NaF scan line. */
#include <friction.h>

#include <stdio.h>
#include <string.h>

#if FRICTION_API_VERSION != 2
#error "this consumer is written for the C API of version 2"
#endif

enum { NX = 8 };

int main(void) {
  char version[32], macros[32], message[256];
  double fx[NX], fy[NX];
  friction_error *err = friction_error_new();
  if (friction_version(version, sizeof version) != FRICTION_OK) return 1;
  snprintf(macros, sizeof macros, "%d.%d.%d", FRICTION_VERSION_MAJOR, FRICTION_VERSION_MINOR, FRICTION_VERSION_PATCH);
  if (strcmp(version, macros) != 0 || friction_api_version() != FRICTION_API_VERSION) {
    fprintf(stderr, "consumer: header %s (API %d), library %s (API %d)\n", macros, FRICTION_API_VERSION, version,
            friction_api_version());
    return 1;
  }
  friction_config *cfg = friction_config_new("afm", err);
  int status = cfg == NULL ? friction_error_status(err) : FRICTION_OK;
  if (status == FRICTION_OK) status = friction_config_set(cfg, "scan.nx", "8", err);
  if (status == FRICTION_OK) status = friction_config_set(cfg, "scan.ny", "1", err);
  if (status == FRICTION_OK) status = friction_config_set_real(cfg, "scan.length", 4.62, err);
  if (status == FRICTION_OK) status = friction_afm_line(cfg, 0, 1, fx, fy, NX, err);
  if (status != FRICTION_OK) {
    friction_error_message(err, message, sizeof message);
    fprintf(stderr, "consumer: %s\n", message);
    return 1;
  }
  friction_config_free(cfg);
  friction_error_free(err);
  printf("friction %s (C API %d): fx[1] = %.6f nN\n", version, FRICTION_API_VERSION, fx[1]);
  return fx[1] != 0.0 ? 0 : 1;
}

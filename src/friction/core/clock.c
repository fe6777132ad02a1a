/* The current time as ISO 8601 UTC text, for the files' `created` attribute
 * (Fortran's date_and_time gives local time only). */
#include <stddef.h>
#include <time.h>

int friction_utc_now(char *buf, size_t len)
{
  time_t now = time(NULL);
  struct tm utc;
  if (now == (time_t)-1 || gmtime_r(&now, &utc) == NULL) return -1;
  return strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &utc) == 0 ? -1 : 0;
}

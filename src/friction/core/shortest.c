/* The shortest text of a double that reads back to it (value_text.f90's
 * shortest), through the C library's correctly rounded printf and strtod:
 * the text the run-time library's es and f0.d edit descriptors gave (they
 * round through the same printf), at a fraction of the cost of Fortran's
 * internal writes and reads, most of a short run's echo of its input.
 * In the "C" locale for this thread while it runs: a host that set another
 * (a decimal comma) must not change the namelist text. */
#define _GNU_SOURCE
#include <float.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* x's text into out (32 bytes; the caller needs no terminating NUL);
 * returns its length (friction_shortest: into *length).  Integers from 1e-3 to 1e15 as "123.0";
 * otherwise the fewest significant digits (from 15: when 15 read back,
 * their rounding is the shortest decimal padded with zeros; else 16 or 17;
 * a subnormal's from 1), written plainly for decimal exponents -3 to 14
 * ("0.0015", "123.456") and else as "1.5e-20". */
static int shortest(double x, char *out)
{
    char buf[48];
    double ax = fabs(x);
    int digits, exponent, n;

    if (x == 0.0) return snprintf(out, 32, "%s", signbit(x) ? "-0.0" : "0.0");
    if (ax >= 1.0e-3 && ax < 1.0e15 && x == trunc(x)) return snprintf(out, 32, "%.1f", x);
    snprintf(buf, sizeof buf, "%.14e", x);
    if (strtod(buf, NULL) == x && ax >= DBL_MIN) {
        const char *p = strchr(buf, 'e') - 1;
        while (*p == '0') --p;
        digits = 0;
        for (const char *q = buf; q <= p; ++q) digits += *q >= '0' && *q <= '9';
        snprintf(buf, sizeof buf, "%.*e", digits - 1, x);
    } else {
        for (digits = ax >= DBL_MIN ? 16 : 1; digits <= 17; ++digits) {
            snprintf(buf, sizeof buf, "%.*e", digits - 1, x);
            if (strtod(buf, NULL) == x) break;
        }
    }
    char *e = strchr(buf, 'e');
    exponent = atoi(e + 1);
    if (exponent >= -3 && exponent < 15) {
        int decimals = digits - 1 - exponent;
        return snprintf(out, 32, "%.*f", decimals > 1 ? decimals : 1, x);
    }
    char *cut = e - 1;
    while (*cut == '0') --cut;
    if (*cut == '.') --cut;
    n = (int)(cut - buf) + 1;
    memcpy(out, buf, (size_t)n);
    return n + snprintf(out + n, 32 - (size_t)n, "e%d", exponent);
}

void friction_shortest(double x, char *out, int *length)
{
    locale_t c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
    locale_t previous = c_locale != (locale_t)0 ? uselocale(c_locale) : (locale_t)0;
    *length = shortest(x, out);
    if (c_locale != (locale_t)0) {
        uselocale(previous);
        freelocale(c_locale);
    }
}

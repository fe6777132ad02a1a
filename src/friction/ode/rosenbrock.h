/* The library's own GSL odeiv2 step types (rosenbrock.c): linearly
 * implicit Rosenbrock methods with the analytic Jacobian.  Like GSL's
 * gsl_odeiv2_step_* they are global pointers to the type. */
#ifndef FRICTION_ROSENBROCK_H
#define FRICTION_ROSENBROCK_H

#include <gsl/gsl_odeiv2.h>

extern const gsl_odeiv2_step_type *friction_step_rodas3;
extern const gsl_odeiv2_step_type *friction_step_rodas4;

#endif

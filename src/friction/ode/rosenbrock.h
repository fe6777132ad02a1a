/* The library's own GSL odeiv2 step types (rosenbrock.c): linearly
 * implicit Rosenbrock methods with the analytic Jacobian.  Like GSL's
 * gsl_odeiv2_step_* they are global pointers to the type. */
#ifndef FRICTION_ROSENBROCK_H
#define FRICTION_ROSENBROCK_H

#include <gsl/gsl_odeiv2.h>

extern const gsl_odeiv2_step_type *friction_step_rodas3;
extern const gsl_odeiv2_step_type *friction_step_rodas4;

/* Whether a step type has a continuous extension, and its value at t within
 * the last accepted step of the stepper state `state` of that type. */
int friction_rosenbrock_has_dense(const gsl_odeiv2_step_type *type);
int friction_rosenbrock_dense(void *state, const gsl_odeiv2_step_type *type, double t, double y[]);

#endif

/* The single-call path of the inverse-dynamics kernel as a CPython extension module: included by
   kernel.c when built with RMT_PYEXT (kin.native.settings.python_extension_flags).

   One C call from Python per evaluation, the result array created here:
     tau(q, qd, qdd, p) -> (n,)     mass_matrix(q, p) -> (n, n)     gravity(q, p) -> (n,)
     coriolis(q, qd, p) -> (n,)     path_coefficients(q, d1, d2, p) -> (n, 3), columns A, B, C
   q, qd, qdd (d1, d2) must be float64 C-contiguous ndarrays (exactly, no subclass) of shape (n,),
   q accepted by rmt_q_ok, the others finite; p float64 (n_p,) (ignored when n_p = 0).  Anything
   else gives None: the Python caller then validates and reports.  Runs with the GIL held. */
#ifndef RMT_DYN_PYEXT_H
#define RMT_DYN_PYEXT_H
#include "rmt_pyext.h"

static const double rmt_py_nop[1] = { 0.0 };

/* Evaluate fun on (q, [qd, [qdd,]] p): `states` state vectors then p. */
static PyObject* rmt_py_call(int fun, int states, PyObject* const* args, Py_ssize_t nargs) {
  if (nargs != states + 1) { PyErr_SetString(PyExc_TypeError, "wrong number of arguments"); return NULL; }
  const double* x[3] = { NULL, NULL, NULL };
  for (int k = 0; k < states; ++k)
    if (!(x[k] = rmt_py_vec(args[k], RMT_N, k ? RMT_PY_FINITE : RMT_PY_JOINTS))) Py_RETURN_NONE;
  const double* p = RMT_NP > 0 ? rmt_py_vec(args[states], RMT_NP, RMT_PY_ANY) : rmt_py_nop;
  if (!p) Py_RETURN_NONE;
  const int C = rmt_cols[fun];
  npy_intp dims[2] = { RMT_N, C };
  PyObject* out = PyArray_SimpleNew(C == 1 ? 1 : 2, dims, NPY_DOUBLE);
  if (!out) return NULL;
  rmt_dyn_one(fun, x[0], x[1], x[2], p, (double*)PyArray_DATA((PyArrayObject*)out));
  return out;
}

static PyObject* rmt_py_tau(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  return rmt_py_call(RMT_F_TAU, 3, args, nargs);
}
static PyObject* rmt_py_mass(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  return rmt_py_call(RMT_F_MASS, 1, args, nargs);
}
static PyObject* rmt_py_grav(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  return rmt_py_call(RMT_F_GRAV, 1, args, nargs);
}
static PyObject* rmt_py_cori(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  return rmt_py_call(RMT_F_CORI, 2, args, nargs);
}
static PyObject* rmt_py_path(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  return rmt_py_call(RMT_F_PATH, 3, args, nargs);
}

static PyMethodDef rmt_py_methods[] = {
  { "tau", RMT_PY_FN(rmt_py_tau), "tau(q, qd, qdd, p): joint torques (n,) of one state, or None" },
  { "mass_matrix", RMT_PY_FN(rmt_py_mass), "mass_matrix(q, p): M (n, n) of one configuration, or None" },
  { "gravity", RMT_PY_FN(rmt_py_grav), "gravity(q, p): g (n,) of one configuration, or None" },
  { "coriolis", RMT_PY_FN(rmt_py_cori), "coriolis(q, qd, p): c (n,) of one state, or None" },
  { "path_coefficients", RMT_PY_FN(rmt_py_path),
    "path_coefficients(q, d1, d2, p): [A B C] (n, 3) of one path point, or None" },
  { NULL, NULL, 0, NULL }
};

RMT_PY_MODULE(rmt_py_methods)
#endif

/* The CPython extension module of the batch kernel: included by kernel.c when built with RMT_PYEXT
   (kin.native.settings.python_extension_flags). */
#ifndef RMT_PYEXT_H
#define RMT_PYEXT_H
/* The single-call path as a CPython extension module: one C call from Python per evaluation, the
   result arrays created here.  Each function takes q, a float64 C-contiguous ndarray of shape (n,)
   whose values rmt_q_ok accepts, and p, the design parameters (float64 (n_p,); ignored when n_p = 0 — the
   library is shared by every chain of the same structure, so the nominal values are the caller's),
   and returns None for anything else (the Python caller then validates and reports).  Runs with
   the GIL held, on stack buffers. */
#include "rmt_pyext.h"

/* (q, p) of a call: q float64 (n,) accepted by rmt_q_ok, p float64 (n_p,) (the caller's nominal parameters). */
static int rmt_py_qp(PyObject* const* args, Py_ssize_t nargs, Py_ssize_t want_args, const double** q,
                     const double** p) {
  if (nargs != want_args) { PyErr_SetString(PyExc_TypeError, "wrong number of arguments"); return -1; }
  *q = rmt_py_vec(args[0], RMT_N, RMT_PY_JOINTS);
  *p = RMT_NP > 0 ? rmt_py_vec(args[1], RMT_NP, RMT_PY_ANY) : rmt_gp;
  return (*q && *p) ? 1 : 0;
}

static PyObject* rmt_py_new(int rows, int cols) {
  npy_intp dims[2] = { rows, cols };
  return PyArray_SimpleNew(2, dims, NPY_DOUBLE);
}

#define RMT_PY_ARGS(k) const double *q, *p; int ok = rmt_py_qp(args, nargs, k, &q, &p); \
  if (ok < 0) return NULL; if (!ok) Py_RETURN_NONE;

static PyObject* rmt_py_fk(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* T = rmt_py_new(4, 4);
  if (!T) return NULL;
  rmt_one(q, p, (double*)PyArray_DATA((PyArrayObject*)T), NULL, NULL, RMT_WANT_T);
  return T;
}

static PyObject* rmt_py_jacobian(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* J = rmt_py_new(6, RMT_N);
  if (!J) return NULL;
  rmt_one(q, p, NULL, (double*)PyArray_DATA((PyArrayObject*)J), NULL, RMT_WANT_J);
  return J;
}

static PyObject* rmt_py_fk_jacobian(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* T = rmt_py_new(4, 4);
  PyObject* J = T ? rmt_py_new(6, RMT_N) : NULL;
  if (!J) { Py_XDECREF(T); return NULL; }
  rmt_one(q, p, (double*)PyArray_DATA((PyArrayObject*)T), (double*)PyArray_DATA((PyArrayObject*)J), NULL,
          RMT_WANT_T | RMT_WANT_J);
  PyObject* res = PyTuple_Pack(2, T, J);
  Py_DECREF(T); Py_DECREF(J);
  return res;
}

/* measures(q, p, flags) -> (manipulability, sigma_min, condition, det) floats (NaN where not wanted) */
static PyObject* rmt_py_measures(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(3)
  long flags = PyLong_AsLong(args[2]);
  if (flags == -1 && PyErr_Occurred()) return NULL;
  double m[4] = { NAN, NAN, NAN, NAN };
  rmt_one(q, p, NULL, NULL, m, (int)flags & (RMT_WANT_MANIP | RMT_WANT_SIGMA));
  return Py_BuildValue("(dddd)", m[0], m[1], m[2], m[3]);
}

static PyMethodDef rmt_py_methods[] = {
  { "fk", RMT_PY_FN(rmt_py_fk), "fk(q, p): T (4, 4) of one configuration, or None" },
  { "jacobian", RMT_PY_FN(rmt_py_jacobian), "jacobian(q, p): J (6, n) of one configuration, or None" },
  { "fk_jacobian", RMT_PY_FN(rmt_py_fk_jacobian), "fk_jacobian(q, p): (T, J) of one configuration, or None" },
  { "measures", RMT_PY_FN(rmt_py_measures), "measures(q, p, flags): 4 measures of one configuration, or None" },
  { NULL, NULL, 0, NULL }
};

RMT_PY_MODULE(rmt_py_methods)
#endif

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
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

/* the data of o when it is a float64 C-contiguous ndarray (n,), its values checked (kind 1: joint
   positions, rmt_q_ok; 2: finite; 0: not checked), else NULL */
static const double* rmt_py_vec(PyObject* o, int n, int kind) {
  if (!PyArray_CheckExact(o)) return NULL;
  PyArrayObject* a = (PyArrayObject*)o;
  if (PyArray_TYPE(a) != NPY_DOUBLE || PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != n
      || !PyArray_ISCARRAY_RO(a) || PyArray_ISBYTESWAPPED(a)) return NULL;
  const double* v = (const double*)PyArray_DATA(a);
  if (kind == 1) { for (int i = 0; i < n; ++i) if (!rmt_q_ok(i, v[i])) return NULL; }
  else if (kind == 2) { for (int i = 0; i < n; ++i) if (!isfinite(v[i])) return NULL; }
  return v;
}

static const double rmt_py_nop[1] = { 0.0 };

/* Evaluate fun on (q, [qd, [qdd,]] p): `states` state vectors then p. */
static PyObject* rmt_py_call(int fun, int states, PyObject* const* args, Py_ssize_t nargs) {
  if (nargs != states + 1) { PyErr_SetString(PyExc_TypeError, "wrong number of arguments"); return NULL; }
  const double* x[3] = { NULL, NULL, NULL };
  for (int k = 0; k < states; ++k)
    if (!(x[k] = rmt_py_vec(args[k], RMT_N, k ? 2 : 1))) Py_RETURN_NONE;
  const double* p = RMT_NP > 0 ? rmt_py_vec(args[states], RMT_NP, 0) : rmt_py_nop;
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
#define RMT_PY_FN(f) (PyCFunction)(void(*)(void))(f), METH_FASTCALL
  { "tau", RMT_PY_FN(rmt_py_tau), "tau(q, qd, qdd, p): joint torques (n,) of one state, or None" },
  { "mass_matrix", RMT_PY_FN(rmt_py_mass), "mass_matrix(q, p): M (n, n) of one configuration, or None" },
  { "gravity", RMT_PY_FN(rmt_py_grav), "gravity(q, p): g (n,) of one configuration, or None" },
  { "coriolis", RMT_PY_FN(rmt_py_cori), "coriolis(q, qd, p): c (n,) of one state, or None" },
  { "path_coefficients", RMT_PY_FN(rmt_py_path),
    "path_coefficients(q, d1, d2, p): [A B C] (n, 3) of one path point, or None" },
  { NULL, NULL, 0, NULL }
};

/* The module is named after the library file (RMT_LIBRARY_NAME, set by the build): CPython keeps
   single-phase extension modules by name, so two libraries must never share one. */
#define RMT_CAT2(a, b) a##b
#define RMT_CAT(a, b) RMT_CAT2(a, b)
#define RMT_STR2(a) #a
#define RMT_STR(a) RMT_STR2(a)
static struct PyModuleDef rmt_py_module = { PyModuleDef_HEAD_INIT, RMT_STR(RMT_LIBRARY_NAME), NULL, -1,
                                            rmt_py_methods };

PyMODINIT_FUNC RMT_CAT(PyInit_, RMT_LIBRARY_NAME)(void) {
  import_array();
  return PyModule_Create(&rmt_py_module);
}
#endif

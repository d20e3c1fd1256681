/* The checker as a CPython extension module (included by motion.c when built with RMT_PYEXT): OMPL's
   state validity checker and motion validator call these directly, one C call per question, with the
   GIL held (a checker's scratch space is then never used twice at once).

   wrap(address, keep) -> capsule: takes ownership of the rmt_motion at `address` (made by
   rmt_motion_new through ctypes) and keeps `keep` (the arrays it reads) alive until the capsule dies;
   state(capsule, q) -> bool and motion(capsule, a, b) -> bool, where q, a, b are OMPL states (anything
   indexable by 0 … n − 1 giving floats) or float64 ndarrays of shape (n,).  A value that cannot be read
   counts as invalid (the error is cleared: an exception must not cross OMPL's C++). */
#ifndef RMT_MOTION_PYEXT_H
#define RMT_MOTION_PYEXT_H
RMT_INLINE int rmt_q_ok(int i, double v) { (void)i; return isfinite(v); }
#include "rmt_pyext.h"

#define CAPSULE_NAME "rmtkit.motion"

typedef struct { rmt_motion *X; PyObject *keep; } py_checker;

static void py_checker_free(PyObject *o)
{
  py_checker *c = (py_checker *)PyCapsule_GetPointer(o, CAPSULE_NAME);
  if (c == NULL) { PyErr_Clear(); return; }
  rmt_motion_free(c->X);
  Py_XDECREF(c->keep);
  free(c);
}

static PyObject *py_wrap(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "wrap(address, keep)"); return NULL; }
  void *p = PyLong_AsVoidPtr(args[0]);
  if (p == NULL) { if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "null checker"); return NULL; }
  py_checker *c = (py_checker *)malloc(sizeof(py_checker));
  if (c == NULL) return PyErr_NoMemory();
  c->X = (rmt_motion *)p;
  c->keep = args[1];
  Py_INCREF(c->keep);
  PyObject *cap = PyCapsule_New(c, CAPSULE_NAME, py_checker_free);
  if (cap == NULL) { Py_DECREF(c->keep); free(c); }
  return cap;
}

/* q[0 .. n) from o; 0 when it cannot be read (error cleared) */
static int py_read_q(PyObject *o, long long n, double *q)
{
  if (PyArray_CheckExact(o)) {
    const double *v = rmt_py_vec(o, (int)n, RMT_PY_ANY);
    if (v == NULL) return 0;
    memcpy(q, v, sizeof(double) * (size_t)n);
    return 1;
  }
  for (long long j = 0; j < n; ++j) {
    PyObject *idx = PyLong_FromLongLong(j);
    PyObject *v = idx ? PyObject_GetItem(o, idx) : NULL;
    Py_XDECREF(idx);
    if (v == NULL) { PyErr_Clear(); return 0; }
    q[j] = PyFloat_AsDouble(v);
    Py_DECREF(v);
    if (q[j] == -1.0 && PyErr_Occurred()) { PyErr_Clear(); return 0; }
  }
  return 1;
}

static rmt_motion *py_checker_of(PyObject *o)
{
  py_checker *c = (py_checker *)PyCapsule_GetPointer(o, CAPSULE_NAME);
  return c ? c->X : NULL;
}

static PyObject *py_state(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "state(checker, q)"); return NULL; }
  rmt_motion *X = py_checker_of(args[0]);
  if (X == NULL) return NULL;
  double q[64];
  if (!py_read_q(args[1], X->n, q)) Py_RETURN_FALSE;
  if (rmt_motion_state(X, q) == RMT_MOTION_CLEAR) Py_RETURN_TRUE;
  Py_RETURN_FALSE;
}

static PyObject *py_motion(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 3) { PyErr_SetString(PyExc_TypeError, "motion(checker, a, b)"); return NULL; }
  rmt_motion *X = py_checker_of(args[0]);
  if (X == NULL) return NULL;
  double a[64], b[64];
  if (!py_read_q(args[1], X->n, a) || !py_read_q(args[2], X->n, b)) Py_RETURN_FALSE;
  rmt_motion_result r;
  X->calls += 1;
  if (rmt_motion_check(X, a, b, 0, 0, &r) == RMT_MOTION_CLEAR) Py_RETURN_TRUE;
  Py_RETURN_FALSE;
}

static PyObject *py_calls(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 1) { PyErr_SetString(PyExc_TypeError, "calls(checker)"); return NULL; }
  rmt_motion *X = py_checker_of(args[0]);
  if (X == NULL) return NULL;
  return PyLong_FromLongLong(X->calls);
}

static PyMethodDef rmt_py_methods[] = {
  { "wrap", RMT_PY_FN(py_wrap), "wrap(address, keep): a capsule owning the checker at address" },
  { "state", RMT_PY_FN(py_state), "state(checker, q): whether configuration q is valid" },
  { "motion", RMT_PY_FN(py_motion), "motion(checker, a, b): whether the motion a -> b is proven valid" },
  { "calls", RMT_PY_FN(py_calls), "calls(checker): the motions motion() has checked so far" },
  { NULL, NULL, 0, NULL }
};

RMT_PY_MODULE(rmt_py_methods)
#endif

/* What every kernel's CPython extension entry shares (kin/compiled/pyext.h, kin/dynamics/pyext.h):
   the Python and numpy headers, the check of one argument array and the module definition.  A kernel
   includes it after defining rmt_q_ok (rmt_common.h) and its sizes. */
#ifndef RMT_PYEXT_COMMON_H
#define RMT_PYEXT_COMMON_H
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>

#define RMT_PY_ANY 0      /* values not checked */
#define RMT_PY_JOINTS 1   /* joint positions: rmt_q_ok */
#define RMT_PY_FINITE 2   /* finite values */

/* The data of o when it is exactly a float64 C-contiguous ndarray of shape (n,) whose values pass
   the check `kind` (RMT_PY_*), else NULL. */
static const double* rmt_py_vec(PyObject* o, int n, int kind) {
  if (!PyArray_CheckExact(o)) return NULL;
  PyArrayObject* a = (PyArrayObject*)o;
  if (PyArray_TYPE(a) != NPY_DOUBLE || PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != n
      || !PyArray_ISCARRAY_RO(a) || PyArray_ISBYTESWAPPED(a)) return NULL;
  const double* v = (const double*)PyArray_DATA(a);
  if (kind == RMT_PY_JOINTS) { for (int i = 0; i < n; ++i) if (!rmt_q_ok(i, v[i])) return NULL; }
  else if (kind == RMT_PY_FINITE) { for (int i = 0; i < n; ++i) if (!isfinite(v[i])) return NULL; }
  return v;
}

#define RMT_PY_FN(f) (PyCFunction)(void(*)(void))(f), METH_FASTCALL

/* The module, named after the library file (RMT_LIBRARY_NAME, set by the build): CPython keeps
   single-phase extension modules by name, so two libraries must never share one. */
#define RMT_CAT2(a, b) a##b
#define RMT_CAT(a, b) RMT_CAT2(a, b)
#define RMT_STR2(a) #a
#define RMT_STR(a) RMT_STR2(a)
#define RMT_PY_MODULE(methods)                                                                      \
  static struct PyModuleDef rmt_py_module = { PyModuleDef_HEAD_INIT, RMT_STR(RMT_LIBRARY_NAME), NULL, -1, \
                                              methods };                                            \
  PyMODINIT_FUNC RMT_CAT(PyInit_, RMT_LIBRARY_NAME)(void) {                                         \
    import_array();                                                                                 \
    return PyModule_Create(&rmt_py_module);                                                         \
  }
#endif

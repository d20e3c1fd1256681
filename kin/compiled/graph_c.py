"""C code of a CasADi SX function, evaluated for a block of configurations at once (structure of arrays).

CasADi's own code generator writes one configuration per call, which leaves the compiler nothing to
vectorise.  :func:`graph_block_c` walks the function's instruction list instead and writes its body
inside a loop over the lanes of a block::

    #pragma omp simd
    for (int l = 0; l < nl; ++l) { double w0, w1, ...; w3 = in0[2*ld + l] * w1; ... }

Every input and output is stored lane-minor (element k of lane l at ``[k*ld + l]``), so each
statement is a unit-stride vector operation across configurations.  Structural zeros of the outputs
are written as 0.  Only the scalar operations a kinematic chain produces are supported; any other
raises :class:`~kin.errors.CompileError` (the caller then falls back to CasADi's virtual machine).
"""
from __future__ import annotations

import math

import casadi as ca

from kin.errors import CompileError

_BINARY = {ca.OP_ADD: "{0} + {1}", ca.OP_SUB: "{0} - {1}", ca.OP_MUL: "{0} * {1}", ca.OP_DIV: "{0} / {1}",
           ca.OP_FMIN: "fmin({0}, {1})", ca.OP_FMAX: "fmax({0}, {1})", ca.OP_ATAN2: "atan2({0}, {1})",
           ca.OP_POW: "pow({0}, {1})", ca.OP_CONSTPOW: "pow({0}, {1})", ca.OP_COPYSIGN: "copysign({0}, {1})"}
_UNARY = {ca.OP_ASSIGN: "{0}", ca.OP_NEG: "-{0}", ca.OP_SQ: "{0} * {0}", ca.OP_TWICE: "2.0 * {0}",
          ca.OP_INV: "1.0 / {0}", ca.OP_SQRT: "sqrt({0})", ca.OP_SIN: "sin({0})", ca.OP_COS: "cos({0})",
          ca.OP_TAN: "tan({0})", ca.OP_FABS: "fabs({0})", ca.OP_EXP: "exp({0})", ca.OP_LOG: "log({0})",
          ca.OP_ASIN: "asin({0})", ca.OP_ACOS: "acos({0})", ca.OP_ATAN: "atan({0})"}


def c_double(x: float) -> str:
    """An exact C literal of a double (hexadecimal floating constant, or INFINITY / NAN)."""
    if math.isnan(x):
        return "NAN"
    if math.isinf(x):
        return "INFINITY" if x > 0 else "(-INFINITY)"
    return f"({float(x).hex()})"


def graph_block_c(f: ca.Function, name: str, inputs: list[str], outputs: list[str]) -> str:
    """C function ``static inline void name(int nl, int ld, <inputs>, <outputs>)`` evaluating ``f``.

    ``inputs``/``outputs`` name the C pointers of ``f``'s inputs and outputs, in order; output j is
    written densely (column-major, ``f.size_out(j)`` elements per lane).  ``nl`` lanes are
    evaluated; ``ld`` is the lane stride of every array.
    """
    if not f.is_a("SXFunction"):
        raise CompileError(f"{f.name()} is not an SX function; cannot generate a block kernel")
    if len(inputs) != f.n_in() or len(outputs) != f.n_out():
        raise CompileError(f"{f.name()}: {f.n_in()} inputs / {f.n_out()} outputs, got names for "
                           f"{len(inputs)} / {len(outputs)}")
    dense = []  # per output: nonzero index → dense column-major index
    zeros = []
    for j in range(f.n_out()):
        sp = f.sparsity_out(j)
        rows, cols = sp.get_triplet()
        idx = [c * sp.size1() + r for r, c in zip(rows, cols)]
        dense.append(idx)
        zeros.extend(f"{outputs[j]}[{k}*ld + l] = 0.0;" for k in sorted(set(range(sp.numel())) - set(idx)))
    lines = []
    for k in range(f.n_instructions()):
        op = f.instruction_id(k)
        i_in, i_out = f.instruction_input(k), f.instruction_output(k)
        if op == ca.OP_INPUT:
            lines.append(f"w{i_out[0]} = {inputs[i_in[0]]}[{i_in[1]}*ld + l];")
        elif op == ca.OP_OUTPUT:
            lines.append(f"{outputs[i_out[0]]}[{dense[i_out[0]][i_out[1]]}*ld + l] = w{i_in[0]};")
        elif op == ca.OP_CONST:
            lines.append(f"w{i_out[0]} = {c_double(f.instruction_constant(k))};")
        elif op in _BINARY:
            lines.append(f"w{i_out[0]} = " + _BINARY[op].format(f"w{i_in[0]}", f"w{i_in[1]}") + ";")
        elif op in _UNARY:
            lines.append(f"w{i_out[0]} = " + _UNARY[op].format(f"w{i_in[0]}") + ";")
        else:
            raise CompileError(f"{f.name()}: operation code {op} has no block-kernel form")
    sz_w = max(f.sz_w(), 1)
    decl = "double " + ", ".join(f"w{i}" for i in range(sz_w)) + ";"
    args = ", ".join([f"const double* restrict {x}" for x in inputs] + [f"double* restrict {x}" for x in outputs])
    body = "\n    ".join([decl, *zeros, *lines])
    return (f"RMT_INLINE void {name}(int nl, int ld, {args}) {{\n"
            f"  RMT_SIMD\n  for (int l = 0; l < nl; ++l) {{\n    {body}\n  }}\n}}\n")

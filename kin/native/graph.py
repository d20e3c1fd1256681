"""A CasADi SX function as an instruction table of a generated header, evaluated by ``rmt_graph.h``.

CasADi's own code generator writes C text, one configuration per call.  :func:`graph_table` walks
the function's instruction list instead and writes it as three tables of numbers and names
(:class:`kin.native.header.Header`), for a function with inputs ``q``, ``p`` and outputs ``T``, ``J``::

    #define G_WORK(X) X(0) X(1) X(2) …                         work variables w0, w1, …
    #define G_ZEROS(ZERO) ZERO(T, 3) …                          structural zeros of the outputs
    #define G_CODE(IN, OUT, CONST, OP1, OP2) \\
      IN(0, q, 0) CONST(1, (0x1.8p+0)) OP2(MUL, 2, 0, 1) OP1(SIN, 3, 2) OUT(T, 12, 3) …

``RMT_GRAPH_EVAL(G)`` of ``kin/native/include/rmt_graph.h`` turns the tables into one statement per
instruction for lane ``l`` of arrays of lane stride ``ld`` (element k of lane l at ``[k*ld + l]``);
a kernel puts it inside an ``omp simd`` loop over the lanes of a block (so every statement is a
vector operation across configurations) or evaluates one configuration (``ld = 1, l = 0``).
Outputs are dense, column-major.  Only the scalar operations a kinematic chain and its Newton–Euler
dynamics produce (sign(q̇) of Coulomb friction included) are supported; any other raises
:class:`~kin.errors.CompileError` (the caller then falls back).
"""
from __future__ import annotations

import casadi as ca

from kin.errors import CompileError
from kin.native.header import Header

_BINARY = {ca.OP_ADD: "ADD", ca.OP_SUB: "SUB", ca.OP_MUL: "MUL", ca.OP_DIV: "DIV", ca.OP_FMIN: "FMIN",
           ca.OP_FMAX: "FMAX", ca.OP_ATAN2: "ATAN2", ca.OP_POW: "POW", ca.OP_CONSTPOW: "POW",
           ca.OP_COPYSIGN: "COPYSIGN"}
_UNARY = {ca.OP_ASSIGN: "ASSIGN", ca.OP_NEG: "NEG", ca.OP_SQ: "SQ", ca.OP_TWICE: "TWICE", ca.OP_INV: "INV",
          ca.OP_SQRT: "SQRT", ca.OP_SIN: "SIN", ca.OP_COS: "COS", ca.OP_TAN: "TAN", ca.OP_FABS: "FABS",
          ca.OP_EXP: "EXP", ca.OP_LOG: "LOG", ca.OP_ASIN: "ASIN", ca.OP_ACOS: "ACOS", ca.OP_ATAN: "ATAN",
          ca.OP_SIGN: "SIGN"}


def graph_table(f: ca.Function, name: str, inputs: list[str], outputs: list[str], header: Header | None = None
                ) -> Header:
    """The tables ``name_WORK``, ``name_ZEROS``, ``name_CODE`` of ``f`` (see the module docstring),
    added to ``header`` (a new one by default).

    ``inputs``/``outputs`` name the C arrays of ``f``'s inputs and outputs, in order; output j is
    written densely (column-major, ``f.size_out(j)`` elements per lane).
    """
    if not f.is_a("SXFunction"):
        raise CompileError(f"{f.name()} is not an SX function; cannot write its instruction table")
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
        zeros.extend(("ZERO", outputs[j], k) for k in sorted(set(range(sp.numel())) - set(idx)))
    code = []
    for k in range(f.n_instructions()):
        op = f.instruction_id(k)
        i_in, i_out = f.instruction_input(k), f.instruction_output(k)
        if op == ca.OP_INPUT:
            code.append(("IN", i_out[0], inputs[i_in[0]], i_in[1]))
        elif op == ca.OP_OUTPUT:
            code.append(("OUT", outputs[i_out[0]], dense[i_out[0]][i_out[1]], i_in[0]))
        elif op == ca.OP_CONST:
            code.append(("CONST", i_out[0], float(f.instruction_constant(k))))
        elif op in _BINARY:
            code.append(("OP2", _BINARY[op], i_out[0], i_in[0], i_in[1]))
        elif op in _UNARY:
            code.append(("OP1", _UNARY[op], i_out[0], i_in[0]))
        else:
            raise CompileError(f"{f.name()}: operation code {op} has no instruction-table form")
    header = header if header is not None else Header(f"instruction table of {f.name()}")
    header.table(f"{name}_WORK", ["X"], [("X", i) for i in range(max(f.sz_w(), 1))])
    header.table(f"{name}_ZEROS", ["ZERO"], zeros)
    header.table(f"{name}_CODE", ["IN", "OUT", "CONST", "OP1", "OP2"], code)
    return header

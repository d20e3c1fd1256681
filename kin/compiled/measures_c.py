"""C code of the dexterity measures for a block of configurations, unrolled for one task-matrix size.

The task Jacobian Jt (m×n, the task rows of J) is handled through its tall form A (R×C, R ≥ C): the
columns of Jt when m ≥ n, else the columns of Jtᵀ.  Both functions below are written out statement
by statement for the chain's R and C (no inner loops, no per-lane branches), inside a loop over the
lanes of a block, so that the compiler vectorises them across configurations like the FK graph:

* ``rmt_qr_measures`` — Householder QR of A: manipulability √det(Jt·Jtᵀ) = |Π r_ii| and, for a
  square Jt, det Jt = Π sign·r_ii (each reflection has determinant −1).  Backward stable, hence
  accurate at a singularity, where the Gram determinant would be rounding noise;
* ``rmt_jacobi_sweep`` / ``rmt_jacobi_finish`` — one-sided (Hestenes) Jacobi SVD: a sweep rotates
  every column pair of every lane whose columns are not yet orthogonal to working precision
  (|γ| > 1e-15·‖x‖‖y‖), the caller repeats sweeps until no lane rotates; the singular values are the
  final column norms.  High relative accuracy for small σ (σ_min down to ~1e-15·σ_max).

Element (k, i) of A for lane l is J[(col·6 + row)·ld + l] of the lane-minor 6×n Jacobian block.
"""
from __future__ import annotations


def _task_index(rows: tuple[int, ...], n: int) -> tuple[int, int, list[list[int]]]:
    """(R, C, src) with src[i][k] the index in the column-major 6×n J of element (k, i) of A."""
    m = len(rows)
    if m >= n:
        return m, n, [[i * 6 + rows[k] for k in range(m)] for i in range(n)]
    return n, m, [[k * 6 + rows[i] for k in range(n)] for i in range(m)]


def _lanes(name: str, args: str, body: list[str], pre: str = "", pragma: str = "RMT_SIMD", ret: str = "void",
           post: str = "") -> str:
    inner = "\n    ".join(body)
    return (f"RMT_INLINE {ret} {name}(int nl, int ld, {args}) {{\n{pre}"
            f"  {pragma}\n  for (int l = 0; l < nl; ++l) {{\n    {inner}\n  }}\n{post}}}\n")


def qr_measures_c(rows: tuple[int, ...], n: int) -> str:
    """``rmt_qr_measures(nl, ld, J, manip, det)``: see the module docstring."""
    R, C, src = _task_index(rows, n)
    a = lambda i, k: f"a{i}_{k}"
    body = [f"double {a(i, k)} = J[{src[i][k]}*ld + l];" for i in range(C) for k in range(R)]
    body.append("double prod = 1.0, sgn = 1.0, tail, acc, norm, v0, vn, f2, f;")
    for c in range(C):
        tail = " + ".join(f"{a(c, k)} * {a(c, k)}" for k in range(c + 1, R)) or "0.0"
        body += [f"tail = {tail};", f"acc = {a(c, c)};", "norm = sqrt(acc * acc + tail);", "prod *= norm;",
                 "sgn = acc > 0 ? sgn : -sgn;"]
        if c == C - 1:
            break
        body += ["v0 = acc > 0 ? acc + norm : acc - norm;", "vn = v0 * v0 + tail;", "f2 = vn > 0 ? 2.0 / vn : 0.0;"]
        for j in range(c + 1, C):
            dot = " + ".join([f"v0 * {a(j, c)}"] + [f"{a(c, k)} * {a(j, k)}" for k in range(c + 1, R)])
            body.append(f"f = f2 * ({dot});")
            body.append(f"{a(j, c)} -= f * v0;")
            body += [f"{a(j, k)} -= f * {a(c, k)};" for k in range(c + 1, R)]
    body.append("manip[l] = prod;")
    body.append("det[l] = sgn * prod;" if R == C and len(rows) == n else "det[l] = NAN;")
    return _lanes("rmt_qr_measures", "const double* restrict J, double* restrict manip, double* restrict det", body)


def jacobi_c(rows: tuple[int, ...], n: int) -> str:
    """``rmt_task_matrix``, ``rmt_jacobi_sweep`` (returns the number of lanes that rotated) and
    ``rmt_jacobi_finish(nl, ld, a, smin, cond)``; ``a`` holds A lane-minor, element (k, i) at
    ``a[(i*R + k)*ld + l]``."""
    R, C, src = _task_index(rows, n)
    a = lambda i, k: f"a{i}_{k}"
    at = lambda i, k: f"a[{i * R + k}*ld + l]"
    copy = [f"{at(i, k)} = J[{src[i][k]}*ld + l];" for i in range(C) for k in range(R)]
    out = [_lanes("rmt_task_matrix", "const double* restrict J, double* restrict a", copy)]
    body = [f"double {a(i, k)} = {at(i, k)};" for i in range(C) for k in range(R)]
    body += [f"double d{i} = " + " + ".join(f"{a(i, k)} * {a(i, k)}" for k in range(R)) + ";" for i in range(C)]
    # t = tan θ of the rotation that zeroes γ: with a = d_j − d_i, b = 2γ (ζ = a/b),
    # t = sign(ζ)/(|ζ| + √(1 + ζ²)) = sign(a)·b / (|a| + √(a² + b²)): one division fewer
    body.append("double gamma, da, b, t, cs, sn, u, v; int rot, any = 0;")
    for i in range(C - 1):
        for j in range(i + 1, C):
            body += ["gamma = " + " + ".join(f"{a(i, k)} * {a(j, k)}" for k in range(R)) + ";",
                     f"rot = gamma * gamma > 1e-30 * (d{i} * d{j});", "any |= rot;",
                     f"da = d{j} - d{i};", "b = rot ? 2.0 * gamma : 1.0;",
                     "t = (da >= 0 ? b : -b) / (fabs(da) + sqrt(da * da + b * b));",
                     "t = rot ? t : 0.0;", "cs = 1.0 / sqrt(1.0 + t * t);", "sn = cs * t;"]
            for k in range(R):
                body += [f"u = {a(i, k)}; v = {a(j, k)};", f"{a(i, k)} = cs * u - sn * v;", f"{a(j, k)} = sn * u + cs * v;"]
            body += [f"d{i} -= t * gamma;", f"d{j} += t * gamma;"]
    body += [f"{at(i, k)} = {a(i, k)};" for i in range(C) for k in range(R)]
    body.append("rotated += any;")
    out.append(_lanes("rmt_jacobi_sweep", "double* restrict a", body, pre="  int rotated = 0;\n",
                      pragma='_Pragma("omp simd reduction(+:rotated)")', ret="int", post="  return rotated;\n"))
    fin = ["double lo = INFINITY, hi = 0.0, sv;"]
    for i in range(C):
        fin += ["sv = sqrt(" + " + ".join(f"{at(i, k)} * {at(i, k)}" for k in range(R)) + ");",
                "lo = sv < lo ? sv : lo;", "hi = sv > hi ? sv : hi;"]
    fin += ["smin[l] = lo;", "cond[l] = lo > 0 ? hi / lo : INFINITY;"]
    out.append(_lanes("rmt_jacobi_finish", "const double* restrict a, double* restrict smin, double* restrict cond",
                      fin))
    return "\n".join(out)

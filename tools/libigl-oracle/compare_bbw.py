#!/usr/bin/env python3
"""Compare sinew's bounded biharmonic weights with libigl's igl.bbw on the same problems.

Reads the case files that `cargo run --release --example bbw_case -- OUT_DIR` writes (see
examples/bbw_case.rs for the format), solves each with libigl's Python binding on the same
vertices, triangles, fixed vertices and fixed values, normalizes the rows as the BBW paper and
sinew do, and prints per case:

- max and mean |w_sinew - w_igl| over all vertices and handles (and per handle);
- the wall-clock and CPU time of both solvers (sinew: Domain::new + interior point + normalize, as
  timed by the example; libigl: the igl.bbw call, which assembles its own operators); both
  solve handles in parallel (rayon; libigl's parallel_for, IGL_NUM_THREADS);
- whether each solver's answer is at the optimum of the per-handle QP (KKT residual and bound
  violation; libigl 2.6's bbw does not say when its active set stops at max_iter);
- per handle, the biharmonic energy 1/2 w^T Q w of both unnormalized solutions (both are
  feasible, so the lower one is nearer the optimum) and a KKT residual; Q = L M^-1 L is built
  from libigl's own cotmatrix and massmatrix;
- how far sinew's cotangent stiffness and lumped mass are from igl.cotmatrix and
  igl.massmatrix(MASSMATRIX_TYPE_VORONOI);
- with clarabel's weights in the case file (bbw_case --reference), the same differences
  against sinew's interior-point reference.

Exits 1 when some case's max difference exceeds --tolerance (default 0.01), 3 when libigl
itself did not reach the optimum of some case (the comparison is then inconclusive: raise
--max-iter), 2 on bad input.
"""

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import igl


def libigl_version():
    try:
        from importlib.metadata import version

        return version("libigl")
    except Exception:  # pragma: no cover - only for odd installs
        return getattr(igl, "__version__", "unknown")


def call_capturing_stderr(fn, *args, **kwargs):
    """Runs fn with the process's stderr (fd 2) sent to a temporary file; returns (result,
    captured text). libigl's C++ code writes its warnings there, past Python's sys.stderr."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            result = fn(*args, **kwargs)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        tmp.seek(0)
        text = tmp.read().decode(errors="replace")
    return result, text


def normalize_rows(w):
    s = w.sum(axis=1, keepdims=True)
    out = w.copy()
    ok = s[:, 0] > 1e-9
    out[ok] /= s[ok]
    return out


def bilaplacian(V, F):
    """Q = L M^-1 L from libigl's own operators (what igl.bbw minimizes, via igl::harmonic)."""
    L = igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    m = M.diagonal()
    inv = np.where(m > 0, 1.0 / np.where(m > 0, m, 1.0), 0.0)
    return (L @ sp.diags(inv) @ L).tocsr(), L, m


def energies(Q, W):
    """Per column: 1/2 w^T Q w."""
    return 0.5 * np.einsum("ij,ij->j", W, Q @ W)


def kkt_residual(Q, W, free, scale):
    """Per column, the largest violation of the box-QP optimality conditions on the free
    vertices (gradient Q w zero strictly inside (0, 1), >= 0 at 0, <= 0 at 1), divided by
    `scale` (one number per case, so that a column whose gradient is all round-off, such as a
    piece held by a single handle, does not look large); and the largest bound violation
    max(-w, w - 1, 0) on the free vertices."""
    G = Q @ W
    residual, outside = [], []
    for j in range(W.shape[1]):
        w, g = W[free, j], G[free, j]
        at_lower = w <= 1e-9
        at_upper = w >= 1.0 - 1e-9
        inside = ~(at_lower | at_upper)
        viol = np.zeros_like(g)
        viol[inside] = np.abs(g[inside])
        viol[at_lower] = np.maximum(0.0, -g[at_lower])
        viol[at_upper] = np.maximum(0.0, g[at_upper])
        residual.append(viol.max() / scale if viol.size else 0.0)
        outside.append(max(0.0, (-w).max(), (w - 1.0).max()) if w.size else 0.0)
    return np.array(residual), np.array(outside)


# A solution whose relative KKT residual or bound violation exceeds these is not at the optimum
# (both solvers reach ~1e-7 or better when their active sets settle).
KKT_TOLERANCE = 1e-5
BOUND_TOLERANCE = 1e-8


def not_optimal(kkt, outside):
    return [j for j in range(kkt.size) if kkt[j] > KKT_TOLERANCE or outside[j] > BOUND_TOLERANCE]


def relative_energy(e, e_igl):
    """(e - e_igl) / e_igl, with columns of negligible energy (a piece held by one handle)
    measured against the largest column's energy instead."""
    floor = 1e-9 * np.abs(e_igl).max()
    return (e - e_igl) / np.maximum(np.abs(e_igl), floor)


def operator_differences(case, V, F, L, m_igl):
    """Max |K_sinew - (-L_igl)| relative to max |L|, and max |m_sinew - m_igl| relative to
    max m, or None when the case file carries no operators."""
    if "stiffness" not in case or "mass" not in case:
        return None
    n = V.shape[0]
    s = case["stiffness"]
    K = sp.csr_matrix((s["values"], (s["rows"], s["cols"])), shape=(n, n))
    dk = abs(K + L).max()
    m_sinew = np.asarray(case["mass"], dtype=float)
    dm = np.abs(m_sinew - m_igl).max()
    return dk / abs(L).max(), dm / m_igl.max(), dk, dm


def fmt_vec(v, spec="{:.2e}"):
    return "[" + ", ".join(spec.format(x) for x in v) + "]"


def compare_case(path, args):
    case = json.loads(Path(path).read_text())
    name = Path(path).stem
    V = np.asarray(case["vertices"], dtype=np.float64)
    if args.dim3:
        V = np.hstack([V, np.zeros((V.shape[0], 1))])
    F = np.asarray(case["triangles"], dtype=np.int64)
    b = np.asarray(case["b"], dtype=np.int64)
    bc = np.asarray(case["bc"], dtype=np.float64)
    W_sinew = np.asarray(case["weights"], dtype=np.float64)
    n, m = W_sinew.shape
    if bc.shape != (b.size, m) or V.shape[0] != n:
        raise ValueError(f"{path}: inconsistent shapes")

    igl_seconds = igl_cpu = float("inf")
    for _ in range(max(1, args.repeat)):
        cpu = time.process_time()
        start = time.perf_counter()
        W_igl_raw, captured = call_capturing_stderr(
            igl.bbw,
            V,
            F,
            b,
            bc,
            partition_unity=False,
            verbosity=0,
            max_iter=args.max_iter,
            inactive_threshold=args.threshold,
            constraint_threshold=args.threshold,
            solution_diff_threshold=args.threshold,
        )
        igl_seconds = min(igl_seconds, time.perf_counter() - start)
        igl_cpu = min(igl_cpu, time.process_time() - cpu)
    # libigl 2.6's bbw says nothing when the active set hits max_iter; it prints only on
    # failure. Convergence is judged below from the KKT conditions instead.
    errors = sum(captured.count(word) for word in ("failed", "error"))
    W_igl = normalize_rows(np.asarray(W_igl_raw))

    diff = np.abs(W_sinew - W_igl)
    result = {
        "name": name,
        "n": n,
        "faces": F.shape[0],
        "handles": m,
        "fixed": b.size,
        "max": float(diff.max()),
        "mean": float(diff.mean()),
        "sinew_s": float(case.get("seconds", float("nan"))),
        "sinew_cpu": float(case.get("cpu_seconds", float("nan"))),
        "igl_s": igl_seconds,
        "igl_cpu": igl_cpu,
        "igl_errors": errors,
    }
    print(
        f"{name}: {n} vertices, {F.shape[0]} triangles, {m} handles, {b.size} fixed vertices"
    )
    print(f"  |w_sinew - w_igl|  max {diff.max():.3e}  mean {diff.mean():.3e}")
    print(
        f"  time (wall / CPU)  sinew {result['sinew_s']:.3f} s / {result['sinew_cpu']:.2f} s "
        f"({case.get('threads', '?')} threads)   libigl {igl_seconds:.3f} s / {igl_cpu:.2f} s "
        f"(IGL_NUM_THREADS={os.environ.get('IGL_NUM_THREADS', 'unset')})"
    )
    print(f"  per handle max     {fmt_vec(diff.max(axis=0))}")
    its = case.get("iterations")
    if its is not None:
        cap = case.get("max_iterations", "?")
        print(
            f"  sinew interior-point iterations {its} (limit {cap}), "
            f"unconverged handles {case.get('unconverged', [])}"
        )
    if errors:
        print(f"  libigl reported {errors} error(s)" + ("" if args.verbose else " (--verbose)"))
    if captured.strip() and args.verbose:
        print("  libigl stderr: " + captured.strip().replace("\n", "\n    "))

    Q, L, m_igl = bilaplacian(V, F)
    ops = operator_differences(case, V, F, L, m_igl)
    if ops is not None:
        rk, rm, dk, dm = ops
        print(
            f"  operators: max |K_sinew + L_igl| {dk:.2e} ({rk:.1e} of max |L|), "
            f"max |m_sinew - m_igl| {dm:.2e} ({rm:.1e} of max m)"
        )
        result["stiffness_rel"] = rk
        result["mass_rel"] = rm

    free = np.setdiff1d(np.arange(n), b)
    U_igl = np.asarray(W_igl_raw)
    e_i = energies(Q, U_igl)
    scale = np.abs(Q @ U_igl)[free].max()
    k_i, o_i = kkt_residual(Q, U_igl, free, scale)
    bad_igl = not_optimal(k_i, o_i)
    result["igl_not_optimal"] = bad_igl
    print(
        f"  libigl (max_iter {args.max_iter}, thresholds {args.threshold:g}): "
        + (f"handles {bad_igl} NOT at the optimum" if bad_igl else "every handle at the optimum")
        + f" (KKT residual max {k_i.max():.1e}, bound violation max {o_i.max():.1e})"
    )
    if "weights_unnormalized" in case:
        U_sinew = np.asarray(case["weights_unnormalized"], dtype=np.float64)
        rel = relative_energy(energies(Q, U_sinew), e_i)
        k_s, o_s = kkt_residual(Q, U_sinew, free, scale)
        bad_sinew = not_optimal(k_s, o_s)
        print(
            "  sinew: "
            + (f"handles {bad_sinew} NOT at the optimum" if bad_sinew else "every handle at the optimum")
            + f" (KKT residual max {k_s.max():.1e}, bound violation max {o_s.max():.1e})"
        )
        print(f"  energy (sinew - igl) / igl per handle {fmt_vec(rel, '{:+.1e}')}")
        print(
            f"  KKT residual per handle (of max |Qw| on free vertices)\n"
            f"    sinew  {fmt_vec(k_s, '{:.1e}')}\n    libigl {fmt_vec(k_i, '{:.1e}')}"
        )
        print(
            f"  row sums before normalizing: sinew [{U_sinew.sum(1).min():.4f}, "
            f"{U_sinew.sum(1).max():.4f}], libigl [{U_igl.sum(1).min():.4f}, "
            f"{U_igl.sum(1).max():.4f}]"
        )
        result["energy_rel_max"] = float(rel.max())
        result["sinew_not_optimal"] = bad_sinew

    if "reference_weights" in case:
        W_ref = np.asarray(case["reference_weights"], dtype=np.float64)
        d_ref_s = np.abs(W_ref - W_sinew)
        d_ref_i = np.abs(W_ref - W_igl)
        print(
            f"  clarabel reference ({case.get('reference_seconds', float('nan')):.3f} s): "
            f"|w_ref - w_sinew| max {d_ref_s.max():.3e}, |w_ref - w_igl| max {d_ref_i.max():.3e}"
        )
        if "reference_weights_unnormalized" in case:
            U_ref = np.asarray(case["reference_weights_unnormalized"], dtype=np.float64)
            rel = relative_energy(energies(Q, U_ref), e_i)
            print(f"    energy (clarabel - igl) / igl per handle {fmt_vec(rel, '{:+.1e}')}")
            k_r, o_r = kkt_residual(Q, U_ref, free, scale)
            print(
                f"    KKT residual clarabel {fmt_vec(k_r, '{:.1e}')}, "
                f"bound violation max {o_r.max():.1e}"
            )
    elif "reference_error" in case:
        print(f"  clarabel reference failed: {case['reference_error']}")
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("cases", nargs="+", help="case JSON files or folders holding them")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        help="largest allowed max |w_sinew - w_igl| per case (default 0.01)",
    )
    parser.add_argument(
        "--max-iter",
        type=int,
        default=1000,
        help="libigl active-set iteration limit (binding default 100; default here 1000 so "
        "libigl converges)",
    )
    parser.add_argument(
        "--threshold",
        type=float,
        default=1e-14,
        help="libigl's inactive/constraint/solution-difference thresholds (default 1e-14, "
        "libigl's own)",
    )
    parser.add_argument(
        "--dim3", action="store_true", help="pass vertices as n x 3 with z = 0 instead of n x 2"
    )
    parser.add_argument(
        "--repeat", type=int, default=1, help="time igl.bbw this many times, report the fastest"
    )
    parser.add_argument("--verbose", action="store_true", help="show libigl's stderr")
    args = parser.parse_args()

    paths = []
    for c in args.cases:
        p = Path(c)
        paths.extend(sorted(p.glob("*.json")) if p.is_dir() else [p])
    if not paths:
        print("no case files", file=sys.stderr)
        return 2

    print(
        f"libigl {libigl_version()}, numpy {np.__version__}, tolerance {args.tolerance:g}"
    )
    failed, inconclusive, suboptimal = [], [], []
    for p in paths:
        try:
            r = compare_case(p, args)
        except (OSError, ValueError, KeyError) as e:
            print(f"{p}: {e}", file=sys.stderr)
            return 2
        if not (r["max"] <= args.tolerance):
            failed.append(r["name"])
        if r["igl_errors"] or r["igl_not_optimal"]:
            inconclusive.append(r["name"])
        if r.get("sinew_not_optimal"):
            suboptimal.append(r["name"])
    print()
    if suboptimal:
        print(
            f"note: sinew stopped short of the optimum in {', '.join(suboptimal)} "
            "(its interior point ends within its tolerances, not at the strict KKT point this "
            "script checks; the unconverged handles above, if any, hit its iteration limit)"
        )
    if failed:
        print(f"FAIL: {', '.join(failed)} differ from libigl by more than {args.tolerance:g}")
        return 1
    if inconclusive:
        print(
            f"INCONCLUSIVE: libigl did not reach the optimum in {', '.join(inconclusive)} "
            "(raise --max-iter)"
        )
        return 3
    print(f"OK: every case within {args.tolerance:g} of libigl")
    return 0


if __name__ == "__main__":
    sys.exit(main())

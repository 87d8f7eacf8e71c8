#!/usr/bin/env python3
"""Sharded audit: `mpirun -np K loom audit` against one process on the audit bench's
scenes written as files (x1: 200 parts, ~1 M triangles, 100 cables; x10: 2,000 parts,
~10 M triangles, 1,000 cables). For K = 1..4 ranks of one thread each (K > 2
oversubscribes this 2-core machine): wall time, the slowest rank's load / index / check,
peak memory per rank, and whether the findings are those of one process (same clashes and
violations by kind, cable and obstacle, values within the audit tolerance; a finding
within the tolerance of its threshold may be in one report only) and byte for byte. Writes bench/results/audit_mpi.csv and audit_mpi.png.

    python3 bench/bench_mpi_audit.py [BUILD_DIR] [--quick | --model]
      --quick: x1 only; --model: only the model for 10^9 triangles on 64 ranks, from the
      CSV of the last run (bench/results/audit_mpi_model.csv)
"""
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = next((a for a in sys.argv[1:] if not a.startswith("--")), os.path.join(ROOT, "build"))
QUICK = "--quick" in sys.argv
LOOM = os.path.join(BUILD, "app", "loom")
WRITER = os.path.join(BUILD, "bench", "bench_write_audit_scene")
RESULTS = os.path.join(ROOT, "bench", "results")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(cmd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.perf_counter() - t0
    if p.returncode not in (0, 1):
        sys.exit(f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout}")
    return wall


# What locates a finding on its cable: decided by where the samples fall, which depends on
# the parts a process holds (the nearest surface sets each sphere-tracing step). So does
# `inside`: whether a sample landed with the axis inside the part, where a chord may cross it.
LOCATION = {"point", "s", "s_begin", "s_end", "s_other", "inside"}


def depth_margin(f):
    """How far a finding is past its threshold (clash depth, clearance shortfall)."""
    if f["kind"] == "clearance":
        return f["required"] - f["clearance"]
    if f["kind"] == "bend-radius":
        return f["min"] - f["radius"]
    return -f["clearance"] if isinstance(f.get("clearance"), (int, float)) else float("inf")


def same_findings(a, b):
    """Same findings up to the audit tolerance: every clash and violation deeper than the
    tolerance in both (same kind, cable, obstacle; value within the tolerance); one within
    the tolerance of its threshold may be in one report only (the certificate allows
    either answer there). Returns (same, borderline findings in one report only)."""
    tol = a["tolerance"]
    borderline = 0
    for key in ("clashes", "violations"):
        def ident(f):
            return json.dumps({k: v for k, v in f.items() if k not in LOCATION | {"clearance", "value", "radius"}},
                              sort_keys=True)
        rest = {}
        for f in b[key]:
            rest.setdefault(ident(f), []).append(f)
        for f in a[key]:
            cands = rest.get(ident(f), [])
            match = next((g for g in cands if all(abs(f[n] - g[n]) <= tol for n in ("clearance", "value", "radius")
                                                  if isinstance(f.get(n), (int, float)))), None)
            if match is not None:
                cands.remove(match)
            elif depth_margin(f) <= tol:
                borderline += 1
            else:
                return False, borderline
        for left in rest.values():
            for g in left:
                if depth_margin(g) > tol:
                    return False, borderline
                borderline += 1
    return a["clamps"] == b["clamps"], borderline


def main():
    work = tempfile.mkdtemp(prefix="loom-mpi-bench-")
    rows = []
    for mult in (1,) if QUICK else (1, 10):
        scene_dir = os.path.join(work, f"x{mult}")
        subprocess.run([WRITER, scene_dir, str(mult)], check=True)
        scene = os.path.join(scene_dir, "scene.toml")
        # One process on one core (the index build would otherwise take both).
        out = os.path.join(scene_dir, "single")
        wall = run(["taskset", "-c", "0", LOOM, "audit", scene, "--threads", "1", "--quiet", "--out", out])
        ref = json.load(open(os.path.join(out, "report.json")))
        t = ref["timing_ms"]
        rows.append([f"x{mult}", "single", 1, ref["triangles"], f"{wall:.3f}", t["load"], t["index"], t["check"],
                     "", "", len(ref["clashes"]), len(ref["violations"]), "yes", 0, "yes"])
        print(rows[-1], flush=True)
        for ranks in (1, 2, 3, 4):
            out = os.path.join(scene_dir, f"ranks{ranks}")
            mpirun = ["mpirun", "--oversubscribe", "-np", str(ranks)]
            if ranks <= 2:
                mpirun += ["--bind-to", "core"]
            wall = run(mpirun + [LOOM, "audit", scene, "--threads", "1", "--quiet", "--out", out])
            rep = json.load(open(os.path.join(out, "report.json")))
            shards = rep["shards"]
            peak = [s["peak_bytes"] / 2**20 for s in shards]
            est = [s["estimated_bytes"] / 2**20 for s in shards]
            identical = all(rep[k] == ref[k] for k in ("clashes", "violations", "clamps"))
            same, borderline = same_findings(ref, rep)
            rows.append([f"x{mult}", "mpi", ranks, rep["triangles"], f"{wall:.3f}",
                         max(s["load_ms"] for s in shards), max(s["index_ms"] for s in shards),
                         max(s["check_ms"] for s in shards), f"{max(peak):.0f}", f"{max(est):.0f}",
                         len(rep["clashes"]), len(rep["violations"]),
                         "yes" if same else "NO", borderline, "yes" if identical else "no"])
            print(rows[-1], flush=True)
    os.makedirs(RESULTS, exist_ok=True)
    csv = os.path.join(RESULTS, "audit_mpi.csv")
    with open(csv, "w") as f:
        f.write("scene,run,ranks,triangles,wall_s,load_ms,index_ms,check_ms,peak_rss_mib_max,estimated_mib_max,"
                "clashes,violations,same_findings,borderline_in_one_only,byte_identical_findings\n")
        for r in rows:
            f.write(",".join(str(x) for x in r) + "\n")
    chart(csv)
    if not QUICK:
        model(csv)


def model(csv, triangles=1e9, ranks=64, cables=1e5):
    """The time and memory of one rank for a whole-aircraft DMU, from the x10 runs on one
    process and on 2 ranks. Assumptions: load and index cost per triangle as measured
    (one core per rank); peak memory per triangle as the 1-rank run's; the check costs
    a + b / K per 1,000 cables of the bench's kind (1–3 m, among parts as dense as the
    bench's): a (paid on every rank: stepping along every cable, and rank 0's cable–cable,
    self and bend passes) and b (shared: the work near parts) fitted to K = 1 and 2; parts
    exchanged once at 1 GB/s per rank (36 bytes per triangle of mesh)."""
    rows = [line.strip().split(",") for line in open(csv)][1:]
    one = next(r for r in rows if r[0] == "x10" and r[1] == "mpi" and r[2] == "1")
    two = next(r for r in rows if r[0] == "x10" and r[1] == "mpi" and r[2] == "2")
    one = one[:3] + [float(x) if x else 0.0 for x in one[3:10]]
    two = two[:3] + [float(x) if x else 0.0 for x in two[3:10]]
    t = one[3]
    load_per_tri, index_per_tri = one[5] / t, one[6] / t
    peak_per_tri = float(one[8]) * 2**20 / t
    b = 2 * (one[7] - two[7])
    a = one[7] - b
    per_rank = triangles / ranks
    kcables = cables / 1000
    load_s = load_per_tri * per_rank / 1000
    index_s = index_per_tri * per_rank / 1000
    exchange_s = 36 * per_rank / 1e9
    check_s = (a * kcables + b * kcables / ranks) / 1000
    with open(os.path.join(RESULTS, "audit_mpi_model.csv"), "w") as f:
        f.write("triangles,ranks,cables,load_s,exchange_s,index_s,check_s,total_s,peak_gib_per_rank,"
                "load_us_per_triangle,index_us_per_triangle,peak_bytes_per_triangle,check_a_ms,check_b_ms\n")
        f.write(f"{triangles:.0f},{ranks},{cables:.0f},{load_s:.1f},{exchange_s:.1f},{index_s:.1f},{check_s:.1f},"
                f"{load_s + exchange_s + index_s + check_s:.1f},{peak_per_tri * per_rank / 2**30:.2f},"
                f"{load_per_tri * 1000:.3f},{index_per_tri * 1000:.3f},{peak_per_tri:.0f},{a:.0f},{b:.0f}\n")


def chart(csv):
    gp = f"""
set datafile separator ','
set terminal pngcairo size 1100,420
set output '{os.path.join(RESULTS, "audit_mpi.png")}'
set multiplot layout 1,2
set title 'Sharded audit, x10 scene (1 thread per rank)'
set xlabel 'MPI ranks'
set ylabel 'seconds'
set key top right
set xtics 1
plot '{csv}' using ($3):((strcol(1) eq 'x10' && strcol(2) eq 'mpi') ? $5 : 1/0) with linespoints title 'wall (mpirun)', \\
     '' using ($3):((strcol(1) eq 'x10' && strcol(2) eq 'mpi') ? ($6+$7+$8)/1000 : 1/0) with linespoints title 'slowest load + slowest index + slowest check'
set title 'Peak memory of the largest rank'
set ylabel 'MiB'
plot '{csv}' using ($3):((strcol(1) eq 'x10' && strcol(2) eq 'mpi') ? $9 : 1/0) with linespoints title 'peak RSS', \\
     '' using ($3):((strcol(1) eq 'x10' && strcol(2) eq 'mpi') ? $10 : 1/0) with linespoints title 'estimate (160 B/triangle)'
unset multiplot
"""
    subprocess.run(["gnuplot"], input=gp, text=True, check=False)


if __name__ == "__main__":
    if "--model" in sys.argv:  # the model alone, from the CSV of the last run
        model(os.path.join(RESULTS, "audit_mpi.csv"))
    else:
        main()

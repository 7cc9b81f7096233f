"""Evaluating 10 million float32 cosines from Python: specula's lobe against NumPy's t**n on
the same array, and against the `specula` command's own streaming rate for the same lobe.

Prints ratios measured in this one run (nothing is asserted). Usage:

    python crates/python/bench/eval_rate.py [--lobe cosquad] [--n 64] [--cli PATH]

The CLI figure is `specula bench lobes --format json`'s all-thread streaming rate (32 M
cosines through 128 MiB buffers, reused); specula here is timed both allocating its result
(``lobe(t)``) and writing into a reused array (``lobe(t, out=out)``), the CLI's condition.
"""

import argparse
import json
import os
import shutil
import subprocess
import time

import numpy as np

import specula

SIZE = 10_000_000


def best_rate(work, repeats=7):
    """Evaluations per second of `work` (best of `repeats`, after one warm-up)."""
    work()
    best = float("inf")
    for _ in range(repeats):
        started = time.perf_counter()
        work()
        best = min(best, time.perf_counter() - started)
    return SIZE / best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lobe", default="cosquad", help="a lobe id, or 'all'")
    parser.add_argument("--n", type=float, default=64.0)
    parser.add_argument("--cli", default=os.environ.get("SPECULA_BIN") or shutil.which("specula"))
    args = parser.parse_args()

    t = np.random.default_rng(0).uniform(0.8, 1.0, SIZE).astype(np.float32)
    out = np.empty_like(t)
    n32 = np.float32(args.n)
    numpy_rate = best_rate(lambda: np.power(t, n32))
    numpy_into = best_rate(lambda: np.power(t, n32, out=out))
    cli = {}
    if args.cli:
        measured = json.loads(
            subprocess.run([args.cli, "bench", "lobes", "--n", f"{args.n:g}", "--format", "json"],
                           capture_output=True, text=True, check=True).stdout
        )
        cli = {r["lobe"]: r["stream"][1] for r in measured["lobes"] if r.get("stream")}
    lobes = specula.lobe_ids() if args.lobe == "all" else [args.lobe]
    print(f"n = {args.n:g}, {SIZE:,} float32 cosines, {os.cpu_count()} CPUs; G evals/s")
    print(f"numpy t**n: {numpy_rate / 1e9:.3f} allocating, {numpy_into / 1e9:.3f} with out=")
    print(f"{'lobe':12s} {'lobe(t)':>8s} {'out=':>8s} {'CLI':>8s}  {'vs numpy':>18s}  {'vs CLI':>6s}")
    for lobe_id in lobes:
        lobe = specula.Lobe(lobe_id, args.n)
        allocating = best_rate(lambda: lobe(t))
        into = best_rate(lambda: lobe(t, out=out))
        stream = cli.get(lobe_id)
        versus_cli = f"{into / stream:6.2f}" if stream else "     -"
        print(f"{lobe_id:12s} {allocating / 1e9:8.3f} {into / 1e9:8.3f} "
              f"{(stream or float('nan')) / 1e9:8.3f}  "
              f"{allocating / numpy_rate:6.2f}x {into / numpy_into:6.2f}x (out=)  {versus_cli}")
    print("vs numpy: allocating against allocating, out= against out=; vs CLI: out= (buffers "
          "reused, the CLI's condition) against `specula bench lobes`' all-thread streaming rate")


if __name__ == "__main__":
    main()

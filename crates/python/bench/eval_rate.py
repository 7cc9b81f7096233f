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
    parser.add_argument("--lobe", default="cosquad")
    parser.add_argument("--n", type=float, default=64.0)
    parser.add_argument("--cli", default=os.environ.get("SPECULA_BIN") or shutil.which("specula"))
    args = parser.parse_args()

    t = np.random.default_rng(0).uniform(0.8, 1.0, SIZE).astype(np.float32)
    out = np.empty_like(t)
    lobe = specula.Lobe(args.lobe, args.n)
    n32 = np.float32(args.n)
    allocating = best_rate(lambda: lobe(t))
    into = best_rate(lambda: lobe(t, out=out))
    numpy_rate = best_rate(lambda: np.power(t, n32))
    numpy_into = best_rate(lambda: np.power(t, n32, out=out))
    print(f"{args.lobe} at n = {args.n:g}, {SIZE:,} float32 cosines, {os.cpu_count()} CPUs")
    print(f"  specula lobe(t)          {allocating / 1e9:7.3f} G evals/s")
    print(f"  specula lobe(t, out=)    {into / 1e9:7.3f} G evals/s")
    print(f"  numpy t**n               {numpy_rate / 1e9:7.3f} G evals/s")
    print(f"  numpy t**n, out=         {numpy_into / 1e9:7.3f} G evals/s")
    print(f"  specula / numpy          {allocating / numpy_rate:7.2f}x (both allocating), "
          f"{into / numpy_into:.2f}x (both out=)")
    if not args.cli:
        print("  (no specula binary: give --cli or set SPECULA_BIN for the CLI ratio)")
        return
    measured = json.loads(
        subprocess.run([args.cli, "bench", "lobes", "--n", f"{args.n:g}", "--format", "json"],
                       capture_output=True, text=True, check=True).stdout
    )
    row = next(r for r in measured["lobes"] if r["lobe"] == args.lobe)
    if not row.get("stream"):
        print("  (the CLI measured no streaming rate)")
        return
    cli_rate = row["stream"][1]
    print(f"  CLI streaming, all threads {cli_rate / 1e9:5.3f} G evals/s ({measured['threads']} threads)")
    print(f"  specula from Python / CLI {into / cli_rate:6.2f} (out=, reused as the CLI's buffers), "
          f"{allocating / cli_rate:.2f} (allocating, which the CLI does not time)")


if __name__ == "__main__":
    main()

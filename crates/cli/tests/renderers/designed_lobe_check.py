"""Checks a lobe file `specula design` wrote, with NumPy and SciPy and none of specula's code.

The formula's text is translated to NumPy (`let x = e;` to an assignment, `^` to `**`, the
language's functions to NumPy's) and evaluated in float64 at every exponent given; the check
then measures, against t^n:

- the epicentre's largest relative error (where t^n >= 1/2, the edge in closed form:
  cos g = 2^(-1/n)), on a dense grid of the angle, refined by SciPy's bounded minimiser
  around the grid's worst point;
- the whole lobe's largest absolute error, on a dense grid of the angle over [0, pi/2];
- that the lobe is 1 at t = 1, in [0, 1], and non-decreasing in t.

Usage: designed_lobe_check.py LOBE.toml MAX_EPICENTRE MAX_WHOLE N1 N2 ...
Prints one JSON line: the worst figures and the exponent of each.
"""

import json
import re
import sys
import tomllib

import numpy as np
from scipy.optimize import minimize_scalar

FUNCTIONS = {
    "exp2": np.exp2,
    "exp": np.exp,
    "log2": np.log2,
    "log": np.log,
    "sqrt": np.sqrt,
    "abs": np.abs,
    "min": np.minimum,
    "max": np.maximum,
    "pow": np.power,
    "floor": np.floor,
    "ceil": np.ceil,
    "acos": np.arccos,
    "cos": np.cos,
    "sin": np.sin,
}


def select(condition, then, otherwise):
    return np.where(condition, then, otherwise)


def to_python(formula):
    """The formula as Python statements; its last expression assigned to `value`."""
    text = re.sub(r"#[^\n]*", "", formula)
    parts = [p.strip() for p in text.split(";") if p.strip()]
    lines = []
    for part in parts[:-1]:
        match = re.fullmatch(r"let\s+([a-z][a-z0-9_]*)\s*=\s*(.*)", part, re.S)
        assert match, f"not a let binding: {part!r}"
        lines.append(f"{match.group(1)} = {match.group(2)}")
    lines.append(f"value = {parts[-1]}")
    return "\n".join(line.replace("^", "**") for line in lines)


def lobe(program, n, t):
    scope = dict(FUNCTIONS, select=select, t=np.asarray(t, dtype=np.float64), n=float(n))
    scope["if"] = select
    exec(program, {"np": np}, scope)
    return np.broadcast_to(np.asarray(scope["value"], dtype=np.float64), np.shape(t))


def figures(program, n):
    g_half = np.arccos(2.0 ** (-1.0 / n))
    g = np.linspace(0.0, g_half, 100_001)
    exact = np.cos(g) ** n
    relative = np.abs(lobe(program, n, np.cos(g)) / exact - 1.0)
    worst = int(np.argmax(relative))
    low, high = g[max(worst - 1, 0)], g[min(worst + 1, len(g) - 1)]
    refined = minimize_scalar(
        lambda x: -abs(lobe(program, n, np.cos(x)) / np.cos(x) ** n - 1.0),
        bounds=(low, high),
        method="bounded",
        options={"xatol": 1e-14},
    )
    epicentre = max(relative[worst], -refined.fun)
    whole_g = np.linspace(0.0, np.pi / 2, 400_001)
    t = np.cos(whole_g)
    values = lobe(program, n, t)
    whole = float(np.max(np.abs(values - t**n)))
    ascending = lobe(program, n, np.linspace(0.0, 1.0, 200_001))
    return {
        "epicentre": float(epicentre),
        "whole": whole,
        "peak": float(lobe(program, n, np.array([1.0]))[0]),
        "in_range": bool(np.all((values >= 0.0) & (values <= 1.0))),
        "falls": float(np.max(ascending[:-1] - ascending[1:])),
    }


def main():
    path, max_epicentre, max_whole = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    exponents = [float(x) for x in sys.argv[4:]]
    with open(path, "rb") as file:
        definition = tomllib.load(file)
    program = to_python(definition["formula"])
    worst = {"epicentre": (0.0, None), "whole": (0.0, None)}
    for n in exponents:
        f = figures(program, n)
        assert abs(f["peak"] - 1.0) < 1e-12, f"n = {n}: peak {f['peak']}"
        assert f["in_range"], f"n = {n}: leaves [0, 1]"
        assert f["falls"] <= 1e-14, f"n = {n}: falls by {f['falls']} as t rises"
        for key in worst:
            if f[key] > worst[key][0]:
                worst[key] = (f[key], n)
    assert worst["epicentre"][0] <= max_epicentre, worst
    assert worst["whole"][0] <= max_whole, worst
    print(json.dumps({key: {"error": e, "n": n} for key, (e, n) in worst.items()}))


main()

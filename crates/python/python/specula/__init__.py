"""specula: specular lobes for Python.

The Phong/Blinn lobe ``cos^n`` and its cheap approximations (modified Schlick, quadratic
Chebyshev, log/exp, the cosine-quadratic ``K_4``, ...), exact in float64 and fast in float32
(the SIMD batch kernels), with the analysis against ``t^n``, the thesis's claims, the
recommendation of a lobe for a target, importance sampling, rendering and shader export.

One library under two faces: the ``specula`` command and this package call the same Rust
functions, so a row here reads the same as the CLI's JSON.

Examples
--------
>>> import numpy as np, specula
>>> lobe = specula.Lobe("cosquad", n=64)
>>> t = np.linspace(0.9, 1.0, 5, dtype=np.float32)
>>> lobe(t).dtype
dtype('float32')
"""

from __future__ import annotations

import json as _json
import os as _os
import warnings as _warnings
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as _np

from . import _specula
from ._specula import Lobe, Microfacet, Volume, default_scene, render, render_volume

__version__: str = _specula.__version__

__all__ = [
    "Lobe",
    "Microfacet",
    "Volume",
    "analyze",
    "claims",
    "cost",
    "default_scene",
    "errors",
    "languages",
    "lobe_ids",
    "models",
    "recommend",
    "design",
    "render",
    "report",
    "render_volume",
    "zones",
]


def lobe_ids() -> List[str]:
    """The built-in lobes' ids, in the registry's order."""
    return _specula.lobe_ids()


def models() -> List[Dict[str, Any]]:
    """The built-in lobes as ``specula models --format json`` lists them (id, summary,
    formula, parameters, origin), each with its plot colour (``colour``, ``#rrggbb``)."""
    return _json.loads(_specula.models_json())


def languages() -> List[str]:
    """The shader languages and renderer formats :meth:`Lobe.shader` writes."""
    return _specula.languages()


def zones(n: float) -> Dict[str, float]:
    """The zones of ``t^n`` (SPEC section 3).

    Returns
    -------
    dict
        ``epicentre_cos`` (``2^(-1/n)``, where ``t^n = 1/2``), ``bloom_cos``
        (``2^(-8/n)``, where ``t^n = 1/256``) and the matching angles in radians.
    """
    return _json.loads(_specula.zones_json(float(n)))


def errors(lobe: Lobe, samples_per_zone: Optional[int] = None) -> Dict[str, float]:
    """A lobe's error figures against ``t^n`` (SPEC section 4), in float64, on
    ``samples_per_zone`` cosines per zone: ``specula analyze``'s (100,001) where omitted, so
    the figures are :func:`analyze`'s.

    Returns
    -------
    dict
        ``epicentre_max_rel``, ``epicentre_max_abs``, ``bloom_max_abs``, ``tail_max_abs``,
        ``rms`` and the rest of ``specula analyze --format json``'s error columns.
    """
    return _json.loads(lobe.errors_json(samples_per_zone))


def analyze(
    lobes: Optional[Sequence[str]] = None,
    n: Union[float, Sequence[float], None] = None,
    precision: str = "f64",
) -> List[Dict[str, Any]]:
    """Every figure of ``specula analyze --format json`` for lobes x exponents.

    Parameters
    ----------
    lobes : sequence of str, optional
        Lobe ids or specifications (``"cosquad:v=5"``, ``"@lobe.toml"``, ``"=t^n"``);
        every built-in lobe when omitted.
    n : float or sequence of float, optional
        Exponents in [1, 1000]; 1, 2, 4, ..., 512, 1000 when omitted.
    precision : {"f64", "f32", "simd"}
        The arithmetic of the error figures.
    """
    if isinstance(lobes, str):
        lobes = [lobes]
    if n is not None and _np.ndim(n) == 0:  # a number, NumPy's scalars included
        n = [n]
    return _json.loads(
        _specula.analyze_json(
            None if lobes is None else list(lobes),
            None if n is None else [float(v) for v in n],
            precision,
        )
    )


def claims(
    exponent_steps: Optional[int] = None,
    samples_per_zone: Optional[int] = None,
    reciprocity_pairs: Optional[int] = None,
    seed: Optional[int] = None,
) -> List[Dict[str, Any]]:
    """The thesis's accuracy and energy claims, measured, with their verdicts.

    The rows of ``specula claims --format json`` (without the hardware claim, which needs
    Yosys), each option the CLI's where omitted (49 exponents, 100,001 samples per zone,
    100,000 direction pairs). Smaller values give a quick, coarser run.
    """
    return _json.loads(
        _specula.claims_json(exponent_steps, samples_per_zone, reciprocity_pairs, seed)
    )


def recommend(
    target: str,
    n: Union[float, str] = 64,
    max_error: float = 0.01,
    zone: str = "epicentre",
    energy_conserving: bool = False,
    lobes: Sequence[str] = (),
    gpu: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Which lobe to ship on ``target`` at an accuracy: the ranked rows of ``specula
    recommend --format json``.

    Parameters
    ----------
    target : {"cpu", "gpu-nvidia", "gpu-amd", "gpu-intel", "fpga"}
    n : float or str
        An exponent, or a range ``"LOW..HIGH"`` the answer must hold over.
    max_error : float
        The largest error allowed, as a fraction (0.01 is 1 %).
    zone : {"epicentre", "bloom", "whole"}
    energy_conserving : bool
        Only lobes whose energy stays within 0.1 % of ``t^n``'s.
    lobes : sequence of str
        More candidates: your own (``"=t^n"``, ``"@lobe.toml"``) or built-ins with other
        parameters.
    gpu : str, optional
        A GPU target's generation by its vendor's name (``"sm_89"``, ``"gfx1100"``,
        ``"tgllp"``, ...); the vendor's current one if omitted.

    Returns
    -------
    list of dict
        One row per lobe (``lobe``, ``datapath``, ``error``, ``rate``, ``unit``,
        ``energy_ratio``, ``meets``, ``pareto``, ``why``), the cheapest that meets it first.
    """
    if isinstance(lobes, str):
        lobes = [lobes]
    reply = _json.loads(
        _specula.recommend_json(
            target, str(n), float(max_error), zone, bool(energy_conserving), list(lobes), gpu
        )
    )
    if reply["note"]:
        _warnings.warn(reply["note"], stacklevel=2)
    return reply["candidates"]


def design(
    target: str,
    n: Union[float, str] = "8..512",
    max_error: float = 0.001,
    max_whole_error: Optional[float] = None,
    energy_tolerance: Optional[float] = None,
    no_transcendentals: bool = False,
    lobes: Sequence[str] = (),
) -> Dict[str, Any]:
    """The cheapest lobe for ``target`` over a range of ``n`` within an accuracy, designed:
    ``specula design --format json``'s answer.

    Parameters
    ----------
    target : {"cpu", "gpu-nvidia", "gpu-amd", "fpga"}
    n : float or str
        An exponent, or a range ``"LOW..HIGH"`` the lobe must hold over.
    max_error : float
        The epicentre's largest relative error, as a fraction (0.001 is 0.1 %).
    max_whole_error : float, optional
        The whole lobe's largest absolute error, as a fraction of the peak (by default
        0.01, or ``max_error`` where that is larger).
    energy_tolerance : float, optional
        Also match ``t^n``'s energy within this fraction at every ``n``.
    no_transcendentals : bool
        Only lobes without a transcendental operation per evaluation.
    lobes : sequence of str
        More lobes ranked beside the built-ins and the designs (``"=t^n"``, ``"@lobe.toml"``).

    Returns
    -------
    dict
        ``lobe`` (the cheapest designed lobe that meets the request, as an id every function
        here takes, or None), ``toml`` (its lobe file's text, or None), ``verdict`` (one
        line), ``designed`` (each family's lobe: ``formula``, ``coefficients``,
        ``epicentre_error``, ``whole_error``, ``rate``, ``meets``, ``pareto``, ``why``, the
        ones that meet first, cheapest first), ``compared`` (``recommend``'s rows for the built-ins on the same
        target and bound), ``pow_rate`` and ``unit``.
    """
    reply = _json.loads(
        _specula.design_json(
            target,
            str(n),
            float(max_error),
            None if max_whole_error is None else float(max_whole_error),
            None if energy_tolerance is None else float(energy_tolerance),
            bool(no_transcendentals),
            [lobes] if isinstance(lobes, str) else list(lobes),
        )
    )
    if reply["note"]:
        _warnings.warn(reply["note"], stacklevel=2)
    best = reply["designed"][0] if reply["designed"] and reply["designed"][0]["meets"] else None
    reply["lobe"] = best["name"] if best else None
    return reply


def cost(target: str, lobe: Lobe) -> Dict[str, Any]:
    """A lobe's cost figure on ``target`` (higher is cheaper): measured on this CPU (one
    thread) or modelled on a GPU family. The FPGA's cost depends on the accuracy (the
    datapath's word length), so it is :func:`recommend`'s, not this function's.

    Returns
    -------
    dict
        ``rate`` and its ``unit``.
    """
    return _json.loads(_specula.cost_json(target, lobe))


def report(
    out: Union[str, "_os.PathLike[str]"] = "report",
    quick: bool = False,
    bench: bool = False,
    lobes: Sequence[str] = (),
    materials: Union[str, "_os.PathLike[str]", None] = None,
) -> str:
    """Writes the report (``specula report``) to the folder ``out``; returns the page's path.

    ``lobes`` adds your own lobes to every section (the built-in ones are always there).
    """
    if isinstance(lobes, str):
        lobes = [lobes]
    return _specula.report(
        _os.fspath(out),
        bool(quick),
        bool(bench),
        list(lobes),
        None if materials is None else _os.fspath(materials),
    )

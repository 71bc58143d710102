"""A system as data: the ``[system]`` table of a scene file, the CLI's ``--system``/``--param``, ``Scene.system``.

A spec is a plain dict, either a built-in by name or a declared potential::

    {"name": "contopoulos", "params": {"eps": 0.25}, "dissipation": "linear"}
    {"potential": "0.5*(x**2 + y**2) - eps*x**2*y**2", "params": {"eps": 0.25}}

with optional overrides of derived quantities (``critical_energy``, ``omega_radius``) for potentials whose
derivation cannot decide. :func:`canonical_spec` gives the one form that enters a scene's hash and its
``scene.json`` (every parameter written out, floats); :func:`system_from_spec` builds the system, once per
spec and process (a declared potential's derivation may take a fraction of a second).

Examples
--------
>>> from hhscatter.model.spec import canonical_spec, system_from_spec
>>> canonical_spec({"name": "henon_heiles", "params": {"lam": 1}})
{'name': 'henon_heiles', 'params': {'lam': 1.0}, 'dissipation': 'linear'}
>>> round(system_from_spec({"name": "henon_heiles"}).critical_energy, 12)
0.166666666667
"""

from __future__ import annotations

import functools
import json
import math
from typing import Any

from hhscatter.errors import ConfigError
from hhscatter.model.base import DISSIPATIONS, System
from hhscatter.model.henon_heiles import HenonHeiles

#: the keys of a system spec (the [system] table): what each holds
SYSTEM_KEYS = {
    "name": "a built-in system's name (a key of hhscatter.model.builtins.BUILTINS)",
    "potential": "V(x, y) as an expression in x, y and the parameters' names",
    "dissipation": "the drag law for γ > 0: 'linear' (−γp, default) or 'quadratic' (−γ|p|p)",
    "params": "the parameters' values, name = number",
    "critical_energy": "override: E_c, when the derivation cannot decide it",
    "omega_radius": "override: the radius of Ω (the closure rule's well), when the derivation cannot decide it",
    "exits": "override: the exits' saddles as [[x, y], ...] or [[x, y, energy], ...], when the derivation cannot "
    "decide them",
}
OVERRIDES = ("critical_energy", "omega_radius", "exits")


def canonical_spec(spec: dict[str, Any] | System) -> dict[str, Any]:
    """canonical_spec(spec) -> the spec's one form: checked keys and types, parameters as floats, the drag law.

    Raises ConfigError naming the key: unknown keys (with the list), neither or both of name/potential, a
    parameter that is not a finite number, an unknown dissipation law.
    """
    if isinstance(spec, System):
        return canonical_spec(spec.spec())
    if not isinstance(spec, dict):
        raise ConfigError(f"system must be a table (name or potential, params, dissipation), got {spec!r}")
    unknown = sorted(set(spec) - set(SYSTEM_KEYS))
    if unknown:
        raise ConfigError(f"unknown [system] keys: {unknown}; allowed: {sorted(SYSTEM_KEYS)}")
    has_name, has_pot = spec.get("name") is not None, spec.get("potential") is not None
    if has_name == has_pot:
        raise ConfigError(
            "[system] needs exactly one of 'name' (a built-in) or 'potential' (an expression in x, y)"
            + (", not both" if has_name else "")
        )
    out: dict[str, Any] = {}
    key = "name" if has_name else "potential"
    if not isinstance(spec[key], str) or not spec[key].strip():
        raise ConfigError(f"system.{key} must be a non-empty string, got {spec[key]!r}")
    out[key] = spec[key].strip()
    params = spec.get("params") or {}
    if not isinstance(params, dict):
        raise ConfigError(f"system.params must be a table of name = number, got {params!r}")
    out["params"] = {}
    for k, v in sorted(params.items()):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
            raise ConfigError(f"system.params.{k} must be a finite number, got {v!r}")
        out["params"][str(k)] = float(v)
    diss = spec.get("dissipation", "linear")
    if diss not in DISSIPATIONS:
        raise ConfigError(f"system.dissipation must be one of {list(DISSIPATIONS)}, got {diss!r}")
    out["dissipation"] = diss
    if spec.get("exits") is not None:
        ex = spec["exits"]
        ok = (
            isinstance(ex, (list, tuple))
            and ex
            and all(
                isinstance(e, (list, tuple))
                and len(e) in (2, 3)
                and all(not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(float(v)) for v in e)
                for e in ex
            )
        )
        if not ok:
            raise ConfigError(f"system.exits must be a list of [x, y] or [x, y, energy] (finite numbers), got {ex!r}")
        out["exits"] = [[float(v) for v in e] for e in ex]
    for k in ("critical_energy", "omega_radius"):
        if spec.get(k) is not None:
            v = spec[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
                raise ConfigError(f"system.{k} must be a finite number, got {v!r}")
            out[k] = float(v)
    return out


def system_from_spec(spec: dict[str, Any] | System) -> System:
    """system_from_spec(spec) -> System, built once per canonical spec and process.

    Hénon–Heiles by name builds :class:`~hhscatter.model.HenonHeiles` directly (closed forms, no
    symbolic derivation); every other spec goes through :func:`hhscatter.model.builtins.make_system`.
    """
    if isinstance(spec, System):
        return spec
    c = canonical_spec(spec)
    return _build(json.dumps(c, sort_keys=True))


def resolve(spec: dict[str, Any] | System) -> tuple[System, dict[str, Any]]:
    """resolve(spec) -> (the system, its full spec): every parameter written out (a built-in's defaults
    included) and the overrides as given — the form a scene stores and hashes (:class:`hhscatter.scene.scene.Scene`).
    """
    if isinstance(spec, System):
        return spec, canonical_spec(spec.spec())
    given = canonical_spec(spec)
    model = _build(json.dumps(given, sort_keys=True))
    return model, canonical_spec({**model.spec(), **{k: given[k] for k in OVERRIDES if k in given}})


@functools.lru_cache(maxsize=64)
def _build(key: str) -> System:
    c = json.loads(key)
    if c.get("name") == "henon_heiles" and not any(k in c for k in OVERRIDES):
        unknown = sorted(set(c["params"]) - {"omega", "lam"})
        if unknown:
            raise ConfigError(f"system.params: henon_heiles has parameters ['lam', 'omega'], got {unknown}")
        try:
            return HenonHeiles(**c["params"], dissipation=c["dissipation"])
        except ValueError as exc:
            raise ConfigError(f"system: {exc}") from None
    from hhscatter.model.builtins import make_system  # deferred: sympy derivations load only for other systems

    return make_system(**c)


__all__ = ["OVERRIDES", "SYSTEM_KEYS", "canonical_spec", "resolve", "system_from_spec"]

"""The built-in systems' gallery for docs/concepts/systems.md: one figure of each potential and the table.

    .venv/bin/python tools/system_gallery.py            # writes docs/concepts/systems/<name>.png, prints the table

Each figure shows V's contours around the well, the level V = E_c (thick), the exits' saddles (×), Ω (the
dashed circle r = omega_radius) and the no-return radius at E = 1.5 E_c (dotted). The table's numbers come from
the systems themselves; tests/docs/test_systems_page.py checks that the page still shows them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hhscatter.model.builtins import BUILTINS  # noqa: E402
from hhscatter.model.spec import system_from_spec  # noqa: E402

#: the parameters a built-in is shown with when not its defaults (n_exit with n = 4: n = 3 is Hénon–Heiles)
SHOWN_WITH = {"n_exit": {"n": 4}}


def gallery() -> list[dict]:
    """The [system] spec of every built-in of the registry, in its order, at the parameters of SHOWN_WITH."""
    return [{"name": name, **({"params": SHOWN_WITH[name]} if name in SHOWN_WITH else {})} for name in BUILTINS]


def _num(v: float) -> str:
    return f"{0.0 if abs(v) < 1e-12 else v:.4g}"


def table_rows():
    """(name, params, E_c, exits, omega_radius, R(1.5 E_c)) of every built-in, at its default parameters."""
    rows = []
    for spec in gallery():
        m = system_from_spec(spec)
        name = spec["name"]
        exits = "; ".join(f"({_num(e.x)}, {_num(e.y)})" for e in m.exits)
        params = ", ".join(f"{k} = {v:g}" for k, v in m.spec()["params"].items())
        rows.append(
            (
                name,
                params,
                m.critical_energy,
                len(m.exits),
                exits,
                m.omega_radius,
                m.no_return_radius(1.5 * m.critical_energy),
            )
        )
    return rows


def markdown_table() -> str:
    out = [
        "| system | parameters | E_c | exits | saddles (x, y) | Ω radius | R(1.5 E_c) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, params, ec, n, exits, om, nr in table_rows():
        exits = exits.replace("-", "−")  # the minus sign, as every number the site prints
        out.append(f"| `{name}` | {params} | {ec:.6g} | {n} | {exits} | {om:.4g} | {nr:.4g} |")
    return "\n".join(out)


def figure(spec: dict, path: Path) -> None:
    from matplotlib.figure import Figure

    m = system_from_spec(spec)
    name = spec["name"] + "".join(f", {k} = {v:g}" for k, v in spec.get("params", {}).items())
    L = 1.6 * max(e.distance for e in m.exits)
    g = np.linspace(-L, L, 401)
    X, Y = np.meshgrid(g, g)
    V = m.potential(X, Y)
    ec = m.critical_energy
    fig = Figure(figsize=(3.4, 3.2), dpi=150, layout="constrained")
    ax = fig.add_subplot()
    levels = ec * np.array([0.1, 0.3, 0.5, 0.7, 0.9, 1.2, 1.6, 2.2])
    ax.contour(X, Y, V, levels=levels, colors="0.55", linewidths=0.6)
    ax.contour(X, Y, V, levels=[ec], colors="k", linewidths=1.4)
    ax.plot([e.x for e in m.exits], [e.y for e in m.exits], "x", color="C3", ms=7, mew=2, label="exits (saddles)")
    t = np.linspace(0, 2 * np.pi, 400)
    r = m.omega_radius
    ax.plot(r * np.cos(t), r * np.sin(t), "--", color="C0", lw=1, label=r"$\Omega$")
    R = m.no_return_radius(1.5 * ec)
    if R < L:
        ax.plot(R * np.cos(t), R * np.sin(t), ":", color="C2", lw=1.2, label=r"$R(1.5E_c)$")
    ax.set_aspect("equal")
    ax.set_xlim(-L, L)
    ax.set_ylim(-L, L)
    ax.set_xlabel("$x$")
    ax.set_ylabel("$y$")
    ax.set_title(f"{name}: $E_c$ = {ec:.4g}", fontsize=9)
    ax.legend(fontsize=6, loc="lower right", framealpha=0.9)
    fig.savefig(path)


def main() -> int:
    out = ROOT / "docs" / "concepts" / "systems"
    out.mkdir(parents=True, exist_ok=True)
    for spec in gallery():
        figure(spec, out / f"{spec['name']}.png")
    print(markdown_table())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Systems: the contract (:mod:`~hhscatter.model.base`) and the built-ins.

The paper's system is :class:`HenonHeiles` (Eqs. (eq:H), (eqn:hh_potential), (eqn:hh_ham)); every system
implements :class:`System` (its potential, the dissipation law, E_c, the exits, Ω, the no-return radius).
A system declared as data is a :class:`DeclaredSystem` (V as text, parsed safely; E_c, exits and Ω derived);
:func:`make_system` builds a built-in (:data:`BUILTINS`) or a declared system from a ``[system]`` table.
"""

from hhscatter.model.base import DISSIPATIONS, Exit, System
from hhscatter.model.builtins import BUILTINS, make_system
from hhscatter.model.declared import DeclaredSystem
from hhscatter.model.henon_heiles import HenonHeiles, equations, hamilton_equations

__all__ = [
    "BUILTINS",
    "DISSIPATIONS",
    "DeclaredSystem",
    "Exit",
    "HenonHeiles",
    "System",
    "equations",
    "hamilton_equations",
    "make_system",
]

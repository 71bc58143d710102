"""Systems: the contract (:mod:`~hhscatter.model.base`) and the built-ins.

The paper's system is :class:`HenonHeiles` (Eqs. (eq:H), (eqn:hh_potential), (eqn:hh_ham)); every system
implements :class:`System` (its potential, the dissipation law, E_c, the exits, Ω, the no-return radius).
"""
from hhscatter.model.base import DISSIPATIONS, Exit, System
from hhscatter.model.henon_heiles import HenonHeiles, equations, hamilton_equations

__all__ = ["DISSIPATIONS", "Exit", "HenonHeiles", "System", "equations", "hamilton_equations"]

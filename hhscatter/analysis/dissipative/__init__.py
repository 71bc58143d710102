"""Dissipative measures: the energy path E(t), transition times τ0, τ1, τ2, the survival model (Eq. (eqn:surv_prob_model)) and its mixture."""

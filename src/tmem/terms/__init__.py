"""Agent terms: pushes each agent adds for itself after the TMEM law's pair terms, ``u[i] += term(i, ...)``.

A term is one class (:class:`tmem.terms.base.AgentTerm`): its scenario table, its record and its
compiled kernel; :data:`TERMS` is the registry, ``table name -> "module:Class"``.  The scenario
gets one optional table per row (:mod:`tmem.scenario.schema`), the driver builds each given term's
record, the step loop adds the terms' pushes agent by agent in the order of :data:`TERMS`
(:mod:`tmem.engine.terms`), and checkpoints save their records; none of them names a term.  The
modules here import no compiler: a term's kernel is compiled when a run binds it.

* :mod:`tmem.terms.pull` — a pull of every agent towards a point, the worked example of a term;
* :mod:`tmem.terms.navigation` — a group flying a mission (N1)-(N5), its table in
  :mod:`tmem.terms.navigation_table` and its planning in :mod:`tmem.terms.navigation_plan`;
* :mod:`tmem.terms.olfati_saber` — Olfati-Saber's flocking law (IEEE TAC 2006): α-, β- and γ-agents;
* :mod:`tmem.terms.vasarhelyi` — Vásárhelyi's flocking law (Science Robotics 2018): repulsion,
  alignment, shill agents, self-propulsion;
* :mod:`tmem.terms.flocking` — the two flocking laws' compiled functions (loaded when a run binds one).
"""

from __future__ import annotations

from tmem._lazy import import_named, submodules

from functools import cache

#: The agent terms, ``scenario table -> "module:Class"``, in the order their pushes are added.
TERMS: dict[str, str] = {
    "pull": "tmem.terms.pull:Pull",
    "olfati_saber": "tmem.terms.olfati_saber:OlfatiSaber",
    "vasarhelyi": "tmem.terms.vasarhelyi:Vasarhelyi",
    "navigation": "tmem.terms.navigation:Navigation",
}


@cache
def term_class(name: str):
    """The :class:`~tmem.terms.base.AgentTerm` registered for the scenario table ``name``.

    Parameters
    ----------
    name : str
        The scenario table's name, a key of :data:`TERMS`.
    """
    return import_named(TERMS[name])

__getattr__ = submodules(__name__)  # noqa: F811  (submodules loaded on first use)

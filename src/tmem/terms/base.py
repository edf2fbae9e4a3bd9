"""The contract of an agent term: its scenario table, its record, its compiled kernel.

An agent term adds a push to each agent's set-point after the TMEM law's pair terms (the
neighbours' pushes (8) and the formation pairs (9)-(11)) and before the gas's walls, which keep
the last word (W2).  It is a *gather*: agent ``i``'s push is computed from what ``i`` knows and
written to ``i``'s row only, ``u[i] += term(i, ...)``, so that agents can be pushed in any order,
on any number of threads (or a GPU's), with the same bits.

A term provides, as class attributes and methods (:mod:`tmem.terms.pull` is a worked example):

* :attr:`AgentTerm.name` and :attr:`AgentTerm.table` — its scenario table ``[name]``, a
  :class:`tmem.scenario.tables.StrictModel` whose ``check(scenario)`` (optional) checks it against
  the rest of the scenario, raising :class:`tmem.scenario.FieldError`;
* :meth:`AgentTerm.record` — the ``NamedTuple`` of arrays and numbers its kernel reads (and may
  change in place, e.g. an estimate it carries from step to step);
* :meth:`AgentTerm.kernel` — its compiled push ``push(i, k, known, agents, box, record)`` (``box``: the
  periodic box's sides, 0 on an open axis): agent
  ``i`` at step ``k``, its state as it knows it ``known[i]`` and ``P*`` (6) in
  ``agents.corrected[i, :, 0]``; it adds to ``agents.setpoint[i]``;
* :attr:`AgentTerm.rebuilt` — the fields of its record a checkpoint does not hold (numbers fixed for
  the run, work space), each with the reason it is made again exactly; every other field is saved;
* :attr:`AgentTerm.local` — whether it reads the agent's own state only, so that a per-agent
  controller (:mod:`tmem.agent`) could run it;
* :attr:`AgentTerm.steers_group` — whether it sets the group's mean motion (a mission): the speed
  synchronisation (S2) then damps the pairs' relative motion without holding their mean square
  speed (S3), which would fight every change of speed the term asks for (``interaction.keep_energy``).
"""

from __future__ import annotations

from typing import Any, ClassVar, NamedTuple


class AgentTerm:
    """An agent term (see the module text).  Subclasses set the class attributes and define the methods."""

    #: The scenario table's name, ``[name]``, and the key of :data:`tmem.terms.TERMS`.
    name: ClassVar[str]
    #: The scenario table.
    table: ClassVar[type]
    #: Fields of the record a checkpoint does not hold, with the reason each is made again exactly.
    rebuilt: ClassVar[dict[str, str]] = {}
    #: Whether the term reads the agent's own state only.
    local: ClassVar[bool] = True
    #: Whether the term sets the group's mean motion (module text).
    steers_group: ClassVar[bool] = False

    @classmethod
    def record(cls, settings: Any, scenario: Any, gains: Any) -> NamedTuple:
        """The record the kernel reads, for a run of ``scenario``.

        Parameters
        ----------
        settings
            The scenario's ``[name]`` table (an instance of :attr:`table`).
        scenario : Scenario
            The whole scenario.
        gains : ndarray, shape (n_law,)
            ``K`` of the law (:func:`tmem.law.modal.gains_for`).
        """
        raise NotImplementedError

    @classmethod
    def kernel(cls) -> Any:
        """The compiled push ``push(i, k, known, agents, box, record)`` (module text)."""
        raise NotImplementedError

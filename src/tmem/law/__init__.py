"""The TMEM law: what each agent computes from what it knows, (4)-(11) and (S1)-(S3).

* :mod:`tmem.law.modal` — the modal gains placing the roots (5), the printed (4) for comparison,
  ``P*`` (6) and the saturation ``|U| <= c_max``;
* :mod:`tmem.law.interaction` — the interaction functions (8), Fig. 3, (10), (11): a registry of
  rows and one compiled kernel each;
* :mod:`tmem.law.coupling` — the pair flag ``F_en``, condition (9) and the energy-matched uncoupling;
* :mod:`tmem.law.synchronise` — speed synchronisation of coupled pairs (S1)-(S3);
* :mod:`tmem.law.record` — the law of a scenario as the step loop's record.
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)

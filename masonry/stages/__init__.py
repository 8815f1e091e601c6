"""Construction stages: does the structure stand at every stage of its laying
(docs/model.md 4.7, docs/stages.md)?

- :mod:`~masonry.stages.orders`: the laying orders, by name;
- :mod:`~masonry.stages.plans`: when each block is laid (:class:`~masonry.stages.plans.StagePlan`);
- :mod:`~masonry.stages.laying`: the joints' mortar by age and the laying rate;
- :mod:`~masonry.stages.analysis`: every stage solved, one row each;
- :mod:`~masonry.stages.records`: what a stage study reports (its extremes, ``run.json``,
  a sweep's summary columns);
- :mod:`~masonry.stages.run`: a stage study into its run folder.

The solver side (the work consecutive stages share) is
:class:`masonry.rbe.sequence.StageSequence`; the figures are in :mod:`masonry.plots.stages`.
"""

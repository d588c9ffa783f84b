"""What a run produces: the recorded outputs (:mod:`~stochpound.results.record`) and the result dataset (:mod:`~stochpound.results.dataset`)."""

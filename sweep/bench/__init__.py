"""Measurement of the engine: speed benchmarks (:mod:`.benchmarks`), the accuracy/time trade
(:mod:`.tradeoff`), agreement between models (:mod:`.agreement`), the cheaper models' errors
against the BEM that the model chooser reads (:mod:`.model_errors`), the error estimate's
coverage of the true error (:mod:`.error_coverage`), a random sample across the declared
ranges (:mod:`.random_sample`), stability at the extremes (:mod:`.extremes`) and the plain
numpy baseline the speed is measured against (:mod:`.plain_solver`).
"""

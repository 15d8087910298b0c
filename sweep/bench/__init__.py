"""Measurement of the engine: speed benchmarks (:mod:`.benchmarks`), the accuracy/time trade
(:mod:`.tradeoff`), agreement between models (:mod:`.agreement`), stability at the extremes
(:mod:`.extremes`) and the plain numpy baseline the speed is measured against
(:mod:`.plain_solver`).
"""

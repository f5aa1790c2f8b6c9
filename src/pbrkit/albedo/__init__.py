"""Directional albedo and what is built on it: the white furnace
(:mod:`~pbrkit.albedo.furnace`), the split-sum / DFG lookup tables and
Kulla-Conty tables (:mod:`~pbrkit.albedo.tables`), multiple-scattering
compensation (:mod:`~pbrkit.albedo.compensation`) and the error of the
real-time approximations (:mod:`~pbrkit.albedo.approximations`)."""

"""Foundations shared by every subpackage: compiled helpers and the kernel
cache (:mod:`~pbrkit.core.jit`), vectors and frames (:mod:`~pbrkit.core.vec`),
colour and tone mapping (:mod:`~pbrkit.core.color`), quadrature rules
(:mod:`~pbrkit.core.quadrature`), texel addressing for bilinear filtering
(:mod:`~pbrkit.core.filtering`), argument checks (:mod:`~pbrkit.core.checks`),
errors (:mod:`~pbrkit.core.errors`) and atomic file output
(:mod:`~pbrkit.core.atomic`)."""

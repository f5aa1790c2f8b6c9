"""Files: images (:mod:`~pbrkit.io.images` dispatching to :mod:`~pbrkit.io.hdr`,
:mod:`~pbrkit.io.exr`, :mod:`~pbrkit.io.pfm`, :mod:`~pbrkit.io.png`), float
packing (:mod:`~pbrkit.io.float_packing`), the KTX2 and DDS containers
(:mod:`~pbrkit.io.ktx2`, :mod:`~pbrkit.io.dds`, :mod:`~pbrkit.io.containers`),
lookup-table files (:mod:`~pbrkit.io.lut_files`), bake files
(:mod:`~pbrkit.io.bake_files`, the chains' KTX2 files :mod:`~pbrkit.io.bake_chains`; the
engines' files are written by :mod:`pbrkit.engines`), environment loading
(:mod:`~pbrkit.io.environment`) and deterministic Matplotlib figures
(:mod:`~pbrkit.io.figures`)."""

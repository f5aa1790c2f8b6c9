"""The application behind the ``pbrkit`` command line (:mod:`pbrkit.cli`): the
demo page (:mod:`~pbrkit.app.demo`, its sections :mod:`~pbrkit.app.demo_sections`,
its warm-up :mod:`~pbrkit.app.warmup`), the furnace and compensation reports
(:mod:`~pbrkit.app.report`) and the batches on Dask (:mod:`~pbrkit.app.batch`,
:mod:`~pbrkit.app.batch_tasks`, :mod:`~pbrkit.app.scheduler`).  It imports the
library, never the command line; the library imports neither."""

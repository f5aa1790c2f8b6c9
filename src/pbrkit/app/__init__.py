"""The application: the ``pbrkit`` command line (:mod:`~pbrkit.app.cli`), the
demo page (:mod:`~pbrkit.app.demo`) and the furnace and compensation reports
(:mod:`~pbrkit.app.report`)."""

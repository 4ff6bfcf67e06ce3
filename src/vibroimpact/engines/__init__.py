"""Time-domain engines: one protocol (:class:`~vibroimpact.engines.base.Engine`), one trajectory type, one registry
(:mod:`~vibroimpact.engines.registry`, name -> engine). Engines know nothing of YAML or xarray."""

"""The shipped study scenes (YAML files beside this one), installed with the package as ``vibroimpact.studies``."""

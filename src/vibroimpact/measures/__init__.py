"""What is judged over a band: the one worst-case entry point over every method that finds a band maximum of a
measure (:mod:`~vibroimpact.measures.worst_case`; the measure table itself is :mod:`vibroimpact.analysis.measures`,
below the closed forms that read it)."""

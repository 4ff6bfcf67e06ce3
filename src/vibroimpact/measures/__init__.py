"""What is judged over a band: the measure table (:mod:`~vibroimpact.measures.table`) and the one worst-case entry
point over every method that finds a band maximum (:mod:`~vibroimpact.measures.worst_case`)."""

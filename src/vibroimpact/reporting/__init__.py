"""HTML pages with figures and tables, drawn from a dataset alone."""

"""A scene's grid run as cases (locally, resumable), gathered into one labelled dataset, written atomically; its cost
estimated before it runs."""

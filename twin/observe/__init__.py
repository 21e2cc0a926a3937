"""Seeing the twin: frames taken after a step (`scene`), recordings, plots, headless pictures, the run report,
the JSON event stream (`events`) and the station doctor (`doctor`, `twin check`)."""

"""Scenes: the pydantic schema (``schema``), the resolved scene the jobs take (``model``),
the defaults a result rests on (``assumptions``) and the plausibility warnings
(``plausibility``)."""

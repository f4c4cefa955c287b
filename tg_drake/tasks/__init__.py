"""Tasks in physics: what each task asks of the object at the end, judged on arrays.

A core (no Drake systems framework): the judges take poses, contact pairs and contents counts
that the supervisor reads off the station's ports, and return a `TaskOutcome`.
"""

"""ProbLog theories of tg_drake, shipped as package data (installed as tg_drake/rules)."""

"""logic stage."""

"""systems stage."""

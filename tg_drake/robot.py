"""The iiwa 14 and WSG 50 facts that several modules share."""

# A posture that keeps the arm clear of the camera's view of the table (radians, joints 1–7).
IIWA_HOME = (0.0, -0.6, 0.0, -1.9, 0.0, 1.0, 0.0)

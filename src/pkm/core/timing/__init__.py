"""Time-optimal motion along a geometric path under actuator limits (issue 46)."""

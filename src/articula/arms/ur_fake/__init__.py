"""A fake Universal Robots controller that speaks the real network protocol (RTDE v2, the
dashboard, the script ports) and runs the MuJoCo twin of a scene's arm behind ur-rtde's
register interface: rtde_types (variables and packing), rtde_session (one RTDE client),
dashboard, script_port (programs), program (ur-rtde's control script), controller (the 2 ms
cycle, safety, the twin) and server (FakeUR: the ports and the cycle's thread). Imports MuJoCo
(the `sim` extra)."""

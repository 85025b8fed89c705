"""The browser viewer (viser): replay a planner's run; steer a live one."""

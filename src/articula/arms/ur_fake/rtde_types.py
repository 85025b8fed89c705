"""RTDE's variables and their wire types (Universal Robots' RTDE guide, PolyScope 5), and the
packing of a recipe's values: big-endian, in the recipe's order, after its one-byte id."""

from __future__ import annotations

import struct
from collections.abc import Sequence

__all__ = ["FORMATS", "INPUTS", "OUTPUTS", "Recipe"]

FORMATS = {  # RTDE type -> struct format (big-endian, no padding)
    "BOOL": "?", "UINT8": "B", "UINT32": "I", "UINT64": "Q", "INT32": "i", "DOUBLE": "d",
    "VECTOR3D": "3d", "VECTOR6D": "6d", "VECTOR6INT32": "6i", "VECTOR6UINT32": "6I",
}  # fmt: skip

_SIX = (
    "target_q target_qd target_qdd target_current target_moment actual_q actual_qd actual_qdd "
    "actual_current actual_current_as_torque actual_moment joint_control_output "
    "actual_TCP_pose actual_TCP_speed actual_TCP_force target_TCP_pose target_TCP_speed "
    "joint_temperatures actual_joint_voltage ft_raw_wrench payload_inertia tcp_offset "
    "actual_current_window joint_position_deviation_ratio"
)
_THREE = "actual_tool_accelerometer payload_cog elbow_position elbow_velocity"
_DOUBLE = (
    "timestamp actual_execution_time speed_scaling target_speed_fraction actual_momentum "
    "actual_main_voltage actual_robot_voltage actual_robot_current standard_analog_input0 "
    "standard_analog_input1 standard_analog_output0 standard_analog_output1 payload "
    "tool_analog_input0 tool_analog_input1 tool_output_current tool_temperature "
    "tcp_force_scalar"
)
_UINT32 = (
    "runtime_state robot_status_bits safety_status_bits output_bit_registers0_to_31 "
    "output_bit_registers32_to_63 tool_mode script_control_line"
)

OUTPUTS: dict[str, str] = (
    dict.fromkeys(_SIX.split(), "VECTOR6D")
    | dict.fromkeys(_THREE.split(), "VECTOR3D")
    | dict.fromkeys(_DOUBLE.split(), "DOUBLE")
    | dict.fromkeys(_UINT32.split(), "UINT32")
    | dict.fromkeys(("robot_mode", "safety_mode", "safety_status", "tool_output_voltage"), "INT32")
    | {"joint_mode": "VECTOR6INT32", "analog_io_types": "UINT8"}
    | dict.fromkeys(("actual_digital_input_bits", "actual_digital_output_bits"), "UINT64")
    | {f"output_int_register_{i}": "INT32" for i in range(48)}
    | {f"output_double_register_{i}": "DOUBLE" for i in range(48)}
    | {f"output_bit_register_{i}": "BOOL" for i in range(64, 128)}
)
"""Output variable name -> its RTDE type."""

INPUTS: dict[str, str] = (
    {f"input_int_register_{i}": "INT32" for i in range(48)}
    | {f"input_double_register_{i}": "DOUBLE" for i in range(48)}
    | {f"input_bit_register_{i}": "BOOL" for i in range(64, 128)}
    | dict.fromkeys(("input_bit_registers0_to_31", "input_bit_registers32_to_63"), "UINT32")
    | {"external_force_torque": "VECTOR6D", "speed_slider_mask": "UINT32"}
    | {"speed_slider_fraction": "DOUBLE"}
    | dict.fromkeys(
        [
            "standard_digital_output_mask",
            "standard_digital_output",
            "configurable_digital_output_mask",
            "configurable_digital_output",
            "tool_digital_output_mask",
            "tool_digital_output",
            "standard_analog_output_mask",
            "standard_analog_output_type",
        ],
        "UINT8",
    )
    | dict.fromkeys(("standard_analog_output_0", "standard_analog_output_1"), "DOUBLE")
)
"""Input variable name -> its RTDE type."""


class Recipe:
    """One recipe: its id, its variables and their types, and their packing.

    Args:
        recipe_id: the id the controller gave it (1..255).
        names: its variables, in the client's order.
        types: each variable's RTDE type ("NOT_FOUND" or "IN_USE" for one refused).
    """

    def __init__(self, recipe_id: int, names: Sequence[str], types: Sequence[str]) -> None:
        self.recipe_id, self.names, self.types = recipe_id, list(names), list(types)
        self.ok = all(t in FORMATS for t in types)
        body = "".join(FORMATS.get(t, "") for t in types)
        self._struct = struct.Struct(">B" + body)
        self._widths = [int(FORMATS[t][:-1] or 1) if t in FORMATS else 0 for t in types]

    def pack(self, values: dict[str, object]) -> bytes:
        """The recipe's data package body: its id, then each variable's value.

        Args:
            values: variable name -> its value (a number or a sequence for a vector).

        Returns:
            The packed bytes.
        """
        flat: list[object] = [self.recipe_id]
        for name, width in zip(self.names, self._widths, strict=True):
            value = values[name]
            flat.extend(value if width > 1 else [value])  # type: ignore[arg-type]
        return self._struct.pack(*flat)

    def unpack(self, body: bytes) -> dict[str, object]:
        """A client's data package body as its variables' values.

        Args:
            body: the bytes after the recipe id.

        Returns:
            Variable name -> its value (a tuple for a vector).
        """
        flat = self._struct.unpack(bytes([self.recipe_id]) + body)[1:]
        values, i = {}, 0
        for name, width in zip(self.names, self._widths, strict=True):
            values[name] = flat[i] if width == 1 else tuple(flat[i : i + width])
            i += width
        return values

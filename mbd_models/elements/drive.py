"""The drive: the input shaft, when the input is driven by angle, as an ``intvelocity`` actuator (kp = shaft
stiffness) on the input hinge, whose activation (the reference angle) integrates the control w_in inside MuJoCo's
RK4 stages (a ``position`` actuator fed w_in t held constant over each step biased the input speed by
O(kp w_in h^2 / I) per unit time, enough to shift a lightly loaded mesh's mean damping force by 5 %), and a
``velocity`` actuator (kv = shaft damping) whose control is w_in, so the shaft damping acts on the twist rate only;
the input and load torques as ``motor`` actuators with gear 1."""

from __future__ import annotations

from gearcheck.mbd_models.elements import ELEMENTS
from gearcheck.mbd_models.elements.base import Element
from gearcheck.mbd_models.mjcf_text import ROTATION, num


@ELEMENTS.register("drive")
class Drive(Element):
    def actuators(self, part, spec) -> list[str]:
        joint_in = f"{spec.members[part.member].label}_{ROTATION}"
        joint_out = f"{spec.members[part.output].label}_{ROTATION}"
        lines = []
        if part.stiffness is not None:
            lines.append(f'    <intvelocity name="input_shaft" joint="{joint_in}" kp="{num(part.stiffness)}" '
                         f'actlimited="false" ctrllimited="false" forcelimited="false"/>')
            if part.damping:
                lines.append(f'    <velocity name="input_shaft_damper" joint="{joint_in}" '
                             f'kv="{num(part.damping)}" ctrllimited="false" forcelimited="false"/>')
        lines.append(f'    <motor name="input_torque" joint="{joint_in}" gear="1" ctrllimited="false" '
                     f'forcelimited="false"/>')
        lines.append(f'    <motor name="output_load" joint="{joint_out}" gear="1" ctrllimited="false" '
                     f'forcelimited="false"/>')
        return lines

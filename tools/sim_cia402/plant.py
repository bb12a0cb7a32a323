"""sim_table's axis plant (runtime/io/axis_plant.*), paper 000 eq. (25)."""

import math

# The sim_table defaults, paper 000 section 5.1 (runtime/io/sim_table.cpp):
# axes 1-3 measured, axis 4 = axis 2's model.
PAPER_TAU = [0.055, 0.056, 0.040, 0.056]
PAPER_GAIN = [35.6206, 36.3872, 52.2836, 36.3872]


class AxisPlant:
    """sim_table's axis (runtime/io/axis_plant.*): theta' = omega,
    omega' = (k u - omega)/tau, u held over a step of h seconds, stepped
    exactly: with a = exp(-h/tau),
      theta+ = theta + tau (1 - a) omega + k (h - tau (1 - a)) u
      omega+ = a omega + k (1 - a) u
    (the closed form of exp([A B; 0 0] h) that axis_plant.cpp computes with
    Eigen's matrix exponential)."""

    def __init__(self, tau, gain, h, position=0.0):
        e = -math.expm1(-h / tau)  # 1 - a, without cancellation
        self.phi12 = tau * e
        self.phi22 = 1.0 - e
        self.g1 = gain * (h - tau * e)
        self.g2 = gain * e
        self.position = position
        self.velocity = 0.0

    def step(self, u):
        x, w = self.position, self.velocity
        self.position = x + self.phi12 * w + self.g1 * u
        self.velocity = self.phi22 * w + self.g2 * u

"""The simulated room, the kinematic drone model and the virtual-drone harness."""

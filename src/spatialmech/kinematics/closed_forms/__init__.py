"""Closed-form kinematics of particular limb and mechanism types: fast vectorised kernels for
hot paths, each cross-checked in the tests against the general closure engine."""

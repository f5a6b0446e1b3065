"""Closed-form kinematics of particular limb and mechanism types: fast vectorised kernels for
hot paths, each cross-checked in the tests against the general closure engine."""

__all__ = ["four_sps_cu", "four_sps_cu_forward", "spherical_rrr", "sps", "three_prs_forward", "translational"]


def __getattr__(name: str):
    """The kernels as attributes (``sm.closed_forms.four_sps_cu``), imported on first use."""
    if name in __all__:
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

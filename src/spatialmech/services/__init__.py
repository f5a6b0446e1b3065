"""Orchestrators below the public API: long-running or stateful work built from the numerical
core that is not itself a driver (no command line, no HTTP).

- :mod:`.screening`: the defect screen of 5-CS linkages on Dask into a Parquet dataset
  (``sm.screen``);
- :mod:`.studio`: the design studio's session state and posing (``sm.studio_session``); the web
  app that serves it is a driver and lives in :mod:`spatialmech.interfaces.studio`.

Layering (tests/test_layering.py): ``spatialmech.api`` imports these; they import the core, the
catalogue and the presentation helpers, never ``spatialmech.api`` nor ``spatialmech.interfaces``.
"""

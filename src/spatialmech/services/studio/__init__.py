"""The design studio's session (:mod:`.session`) and output-link posing (:mod:`.posing`)."""

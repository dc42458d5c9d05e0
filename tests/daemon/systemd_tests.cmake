# Filled in by the work on neuflowd (systemd).

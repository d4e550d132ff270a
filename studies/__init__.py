"""Study runners: the scripts that make the measured tables of ``docs/studies/`` (run from the repository
root as modules, e.g. ``/usr/bin/python3 -m studies.fem_profile``, or ``bash studies/NAME.sh``;
``bash docs/regenerate.sh list`` names what each feeds and what it costs)."""

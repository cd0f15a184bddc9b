"""The installed Python module (install test, step f): imported from PYTHONPATH (the prefix's
site directory), it solves a scene. Prints the module's file and the run's status."""
import sys

import lpshoot

r = lpshoot.solve(sys.argv[1], {"horizon.N": 60})
if not r.converged:
    sys.exit(f"the installed module's solve did not converge: {r.message}")
print(lpshoot.__file__, r.status)

"""``python -m pegame.report``: see :func:`pegame.report.main`."""

import sys

from pegame.report import main

sys.exit(main())

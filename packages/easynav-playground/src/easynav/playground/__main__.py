"""``python -m easynav.playground``: the playground robot (see ``easynav-playground --help``)."""

import sys

from easynav.playground.ros.playground_main import main

sys.exit(main())

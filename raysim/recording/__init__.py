"""Recording writers: they only serialise; physics lives in sensors and the scene."""

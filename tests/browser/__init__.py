"""Browser tests (collected only with TUNNELKIT_BROWSER=1; see conftest.py)."""

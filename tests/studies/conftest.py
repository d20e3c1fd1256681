"""Shared fixtures of the study tests."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def report_browser():
    """One headless Chromium for the session (tests/browser.py); skips where Chromium cannot be had."""
    from tests.browser import ReportBrowser, ensure_chromium
    browser = ReportBrowser(ensure_chromium())
    yield browser
    browser.close()

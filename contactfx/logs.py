"""The contactfx logger and the stage its lines belong to (e.g. the coarse predictor's solve).

Inside `with stage("predictor"):` every line of the "contactfx" logger that does not already
name the stage is prefixed with it, so the linear algebra (which knows no stage) is labelled
too.
"""

from __future__ import annotations

import contextvars
import logging
from collections.abc import Iterator
from contextlib import contextmanager

_STAGE: contextvars.ContextVar[str] = contextvars.ContextVar("contactfx_stage", default="")


class StageFilter(logging.Filter):
    """Prefix a record with the current stage unless its text already starts with it."""

    def filter(self, record: logging.LogRecord) -> bool:
        """Label the record (never drops one)."""
        label = _STAGE.get()
        if label and not record.getMessage().startswith(label):
            record.msg = f"{label}: {record.getMessage()}"
            record.args = None
        return True


log = logging.getLogger("contactfx")
if not any(isinstance(f, StageFilter) for f in log.filters):
    log.addFilter(StageFilter())


@contextmanager
def stage(label: str) -> Iterator[None]:
    """Label every log line written inside the block with `label`."""
    token = _STAGE.set(label)
    try:
        yield
    finally:
        _STAGE.reset(token)

"""A running Dask scheduler's address, checked and normalised (``[tcp://]HOST:PORT``, the scheme
one of :data:`SCHEMES`): the ``scheduler`` option of every parallel command
(:func:`tunnelkit._parallel.parallel_options`)."""

from __future__ import annotations

from urllib.parse import urlsplit

__all__ = ["SCHEMES", "scheduler_address"]

SCHEMES = ("tcp", "tls", "ws", "wss")


def scheduler_address(scheduler) -> str:
    """``scheduler`` (``[tcp://]HOST:PORT``) checked, ``tcp://`` added when no scheme is given."""
    if not isinstance(scheduler, str):
        raise TypeError(
            f"scheduler: expected an address such as 'tcp://HOST:8786', got {scheduler!r}"
        )
    text = scheduler.strip()
    full = text if "://" in text else f"tcp://{text}"
    bad = ValueError(
        f"scheduler: expected an address such as 'tcp://HOST:8786' "
        f"(scheme one of {', '.join(SCHEMES)}), got {scheduler!r}"
    )
    try:
        parts = urlsplit(full)
        port = parts.port
    except ValueError as exc:
        raise bad from exc
    if (
        parts.scheme not in SCHEMES
        or not parts.hostname
        or port is None
        or port == 0
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username
    ):
        raise bad
    return full.rstrip("/")

"""meshcat's server (its ZMQ-to-WebSocket bridge) with its web server bound to one address: ``legkin view`` serves
the scene on 127.0.0.1 unless ``--host`` opens it to a network on purpose.

meshcat 0.3's own server listens on every interface (tornado's ``listen(port)``), so that anyone on the network could
open the scene; this module runs the same bridge with ``listen(port, address=host)``. Its ZeroMQ socket, which only
legkin itself talks to, stays on 127.0.0.1. Run as ``python -m legkin._meshcat_server --host ADDRESS``; it prints
``zmq_url=...`` and ``web_url=...`` as meshcat's server does.
"""

from __future__ import annotations

import argparse
import socket
from typing import Any

#: The address ``legkin view`` serves on by default: this machine only.
LOCAL = "127.0.0.1"


def _bridge(host: str) -> Any:
    """meshcat's ``ZMQWebSocketBridge`` whose web server listens on ``host`` only (ZeroMQ on 127.0.0.1)."""
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class Bridge(ZMQWebSocketBridge):  # type: ignore[misc]
        def make_app(self) -> Any:
            app = super().make_app()
            listen = app.listen
            app.listen = lambda port, **kw: listen(port, address=host, **kw)
            return app

    bridge = Bridge(host=LOCAL)
    shown = socket.gethostname() if host in ("", "0.0.0.0", "::") else host
    bridge.web_url = bridge.web_url.replace(f"//{LOCAL}:", f"//{shown}:")
    return bridge


def main(argv: list[str] | None = None) -> None:
    """Serve until interrupted (``--host``: the address of the web server, default 127.0.0.1)."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--host", default=LOCAL)
    args = parser.parse_args(argv)
    bridge = _bridge(args.host)
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()

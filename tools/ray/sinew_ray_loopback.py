"""Keeps a Ray cluster on the loopback interface when SINEW_RAY_LOOPBACK=1 (the test's cluster).

Ray replaces a loopback address given as a node's or the cluster's address (127.0.0.1,
localhost) by the machine's network address (`ray._private.services.resolve_ip_for_localhost`,
used by `ray start --node-ip-address`, by the bootstrap address and by `ray.init`), so the nodes
of a one-machine cluster would talk to each other over that address. With this module imported
a loopback address stays as given, and every Ray process talks over 127.0.0.1 only.

install.sh makes every Python of tools/ray/.venv import it at start-up (a .pth file) when the
variable is set; without it nothing changes.
"""

import ray._private.services as _services

_original = _services.resolve_ip_for_localhost


def _keep_loopback(host):
    if host in ("127.0.0.1", "localhost"):
        return "127.0.0.1"
    return _original(host)


_services.resolve_ip_for_localhost = _keep_loopback

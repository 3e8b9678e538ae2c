"""Starting Ray for the engine: a local instance, or joining a cluster that answers, failing
fast with a fix when none does; and Ray itself, or how to install it."""

from __future__ import annotations

import os
import socket
from types import ModuleType

from simoun_agent.config import SetupError

__all__ = ["connect", "load_ray"]

CONNECT_TIMEOUT_S = 5.0
"""How long ``--address HOST:PORT`` may take to answer before the sweep gives up."""


def load_ray() -> ModuleType:
    """Ray, or a SetupError saying how to install it."""
    try:
        import ray
        from ray import tune  # noqa: F401  (fails too when ray is there without the tune extra)
    except ImportError:
        raise SetupError(
            "simoun-sweep runs on Ray Tune, which is not installed; install it with: "
            "pip install 'simoun[lab]'"
        ) from None
    return ray


def connect(ray: ModuleType, address: str | None, num_cpus: int | None) -> bool:
    """Start a local Ray instance (``address`` None) or join a cluster (``auto``, ``HOST:PORT``,
    ``ray://HOST:PORT``); an address where no Ray cluster answers fails within seconds.

    As in ``ray.init``, the ``RAY_ADDRESS`` environment variable stands for a missing or ``auto``
    address, and is probed the same way. ``num_cpus`` sizes a local instance only: with a
    cluster it is refused, since the cluster's own CPUs run the trials.

    Returns whether Ray was started here (False when this process had already initialized it,
    e.g. a notebook that called ``ray.init`` itself): only then does the sweep shut it down.
    """
    if num_cpus is not None and num_cpus < 1:
        raise SetupError(
            f"--num-cpus {num_cpus}: a local Ray instance needs at least 1 CPU to run a trial; "
            "drop --num-cpus to give it this machine's, or pass 1 or more"
        )
    source = f"--address {address}"
    from_environment = os.environ.get("RAY_ADDRESS", "").strip()
    if from_environment and address in (None, "auto"):
        address, source = from_environment, f"RAY_ADDRESS={from_environment}"
    if address is not None and num_cpus is not None:
        unset = "unset RAY_ADDRESS" if source.startswith("RAY_") else "drop --address"
        raise SetupError(
            f"--num-cpus {num_cpus} with {source}: --num-cpus sizes a local Ray instance, and a "
            f"cluster runs trials on its own CPUs; drop --num-cpus to run on the cluster, or "
            f"{unset} to run on a local instance of {num_cpus} CPUs"
        )
    if ray.is_initialized():
        return False
    if address is None:
        # Ray starts its workers at nice 15, below every other process: on a 2-core machine
        # shared with a test run, each one-thread trial got about a quarter of a core, and the
        # wall times a study records measured the other work. At 0 they share the CPU evenly.
        ray.init(
            address="local",
            num_cpus=num_cpus,
            include_dashboard=False,
            _system_config={"worker_niceness": 0},
        )
        return True
    local = "unset RAY_ADDRESS" if source.startswith("RAY_") else "drop --address"
    fix = (
        "start a cluster with `ray start --head` (and `ray start --address HEAD:6379` on the "
        f"other machines), or {local} to run on a local Ray instance"
    )
    if address != "auto":
        host, _, port = address.removeprefix("ray://").rpartition(":")
        if not host or not port.isdigit():
            raise SetupError(f"{source}: {address!r} is not HOST:PORT, ray://HOST:PORT or auto")
        problem = probe_tcp(host, int(port)) if address.startswith("ray://") else probe_gcs(address)
        if problem:
            raise SetupError(f"{source}: no Ray cluster answers ({problem}); {fix}")
    try:
        ray.init(address=address)
    except (ConnectionError, RuntimeError, ValueError) as err:
        raise SetupError(f"{source}: cannot join a Ray cluster ({err}); {fix}") from None
    return True


def probe_tcp(host: str, port: int) -> str | None:
    """Why nothing listens at ``host:port``, or None when something does."""
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as err:
        return err.strerror or str(err)
    return None


def probe_gcs(address: str) -> str | None:
    """Why no Ray head (GCS) answers at ``address``, or None when one does.

    ``ray.init`` retries a silent or foreign server for about 20 s; one gRPC call with a
    deadline answers at once. A head that wants an auth token still proves it is there.
    """
    import grpc
    from ray.core.generated import gcs_service_pb2, gcs_service_pb2_grpc

    with grpc.insecure_channel(address) as channel:
        stub = gcs_service_pb2_grpc.NodeInfoGcsServiceStub(channel)
        try:
            stub.GetClusterId(gcs_service_pb2.GetClusterIdRequest(), timeout=CONNECT_TIMEOUT_S)
        except grpc.RpcError as err:
            if err.code() != grpc.StatusCode.UNAUTHENTICATED:
                return f"{err.code().name}: {err.details()}"
    return None

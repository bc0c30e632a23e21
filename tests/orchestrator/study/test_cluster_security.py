"""A sweep's LocalCluster: only a process with its credentials can run code on it; no dashboard unless asked."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import urllib.request

import psutil
import pytest
from distributed import Client

from orchestrator.study.cluster import locked_down_local_cluster
from tests.helpers.studies import free_port

pytestmark = pytest.mark.slow

#: another local process trying to run code on the cluster's workers: it would create the marker file
ATTACKER = textwrap.dedent('''
    import sys
    from pathlib import Path
    from distributed import Client, Security

    address, marker, mode = sys.argv[1], sys.argv[2], sys.argv[3]
    if mode == "credentials":
        ca, cert, key = sys.argv[4:7]
        security = Security(tls_ca_file=ca, tls_client_cert=cert, tls_client_key=key, require_encryption=True)
        attempts = [(address, security)]
    else:
        attempts = [
            (address, None),                                 # no credentials at all
            (address, Security.temporary()),                 # credentials of its own
            (address.replace("tls://", "tcp://"), None),     # plain TCP to the same port
        ]
    ran = 0
    for target, security in attempts:
        try:
            kwargs = {"security": security} if security is not None else {}
            with Client(target, timeout="5s", **kwargs) as client:
                client.run(lambda m=marker: Path(m).write_text("ran"))
                ran += 1
                print("RAN", target, flush=True)
        except Exception as exc:
            print("REFUSED", target, type(exc).__name__, flush=True)
    sys.exit(0 if ran == 0 else 3)
''')


def listening(process: psutil.Process) -> list[tuple[str, int]]:
    """(address, port) of every socket the process and its children listen on."""
    out = []
    for p in [process, *process.children(recursive=True)]:
        for con in p.net_connections(kind="inet"):
            if con.status == psutil.CONN_LISTEN:
                out.append((con.laddr.ip, con.laddr.port))
    return out


def _pem_files(security, folder):
    paths = []
    for name, text in (("ca.pem", security.tls_ca_file), ("cert.pem", security.tls_client_cert),
                       ("key.pem", security.tls_client_key)):
        path = folder / name
        path.write_text(text)
        paths.append(str(path))
    return paths


def test_only_a_process_with_the_sweep_credentials_can_run_code_on_its_workers(tmp_path):
    script = tmp_path / "attacker.py"
    script.write_text(ATTACKER)
    marker = tmp_path / "marker"
    cluster = locked_down_local_cluster(workers=1)
    try:
        address = cluster.scheduler_address
        assert address.startswith("tls://127.0.0.1:")
        with Client(cluster, security=cluster.security) as client:  # the sweep itself
            assert sum(client.run(lambda: 1).values()) == 1
        attack = subprocess.run([sys.executable, str(script), address, str(marker), "none"], capture_output=True,
                                text=True, timeout=180)
        assert attack.returncode == 0, attack.stdout + attack.stderr
        assert attack.stdout.count("REFUSED") == 3 and not marker.exists()
        # the same script with the sweep's credentials does run code: the refusals above were the credentials'
        with_keys = subprocess.run([sys.executable, str(script), address, str(marker), "credentials",
                                    *_pem_files(cluster.security, tmp_path)], capture_output=True, text=True,
                                   timeout=180)
        assert with_keys.returncode == 3 and marker.read_text() == "ran", with_keys.stdout + with_keys.stderr
    finally:
        cluster.close()


def test_nothing_listens_on_8787_or_beyond_loopback_unless_a_dashboard_is_asked_for():
    me = psutil.Process()
    before = set(listening(me))
    cluster = locked_down_local_cluster(workers=1)
    try:
        ports = set(listening(me)) - before
        assert ports and all(ip == "127.0.0.1" for ip, _ in ports), ports
        assert 8787 not in {port for _, port in ports}
        http_port = cluster.scheduler.http_server.port
        with urllib.request.urlopen(f"http://127.0.0.1:{http_port}/health", timeout=10) as reply:
            assert reply.read() == b"ok"  # the health check is all the HTTP server serves
        for path in ("/status", "/info/main/workers.html", "/json/identity.json", "/metrics", "/proxy/1/127.0.0.1/"):
            with pytest.raises(urllib.error.HTTPError, match="404"):
                urllib.request.urlopen(f"http://127.0.0.1:{http_port}{path}", timeout=10)
    finally:
        cluster.close()
    port = free_port()
    asked = locked_down_local_cluster(workers=1, dashboard_address=f"127.0.0.1:{port}")
    try:
        assert ("127.0.0.1", port) in listening(me)
        assert asked.scheduler.http_server.port == port
    finally:
        asked.close()

"""A minimal REAPI worker for compiler/tests/bazel.rs: runs the actions BuildGrid's scheduler
leases to it, through the Remote Workers API (google.devtools.remoteworkers.v1test2).

Written for the test (no registry reachable from CI has a worker: BuildGrid's own bot was removed
in 2024 and buildbox-worker is not packaged). One session, one lease at a time: take the lease
(PENDING -> ACTIVE), fetch the Action, its Command and its input tree from the CAS, run the command
in a fresh folder with the Command's environment, upload the declared outputs, stdout and stderr,
and complete the lease with the ActionResult. It uses BuildGrid's generated protocol modules, so
it runs with the Python of BuildGrid's virtual environment.

Usage: python worker.py ADDRESS WORKDIR   (ADDRESS like 127.0.0.1:50051; the instance is "")
"""

import hashlib
import os
import stat
import subprocess
import sys
import tempfile
import time
import uuid

import grpc
from buildgrid._protos.build.bazel.remote.execution.v2 import remote_execution_pb2 as re
from buildgrid._protos.build.bazel.remote.execution.v2 import remote_execution_pb2_grpc as re_grpc
from buildgrid._protos.google.bytestream import bytestream_pb2, bytestream_pb2_grpc
from buildgrid._protos.google.devtools.remoteworkers.v1test2 import bots_pb2, bots_pb2_grpc, worker_pb2

CHUNK = 1 << 20  # bytes per ByteStream message


def digest_of(data):
    return re.Digest(hash=hashlib.sha256(data).hexdigest(), size_bytes=len(data))


class Cas:
    """Reads and writes blobs through the ByteStream API (any size)."""

    def __init__(self, channel):
        self.bytestream = bytestream_pb2_grpc.ByteStreamStub(channel)

    def read(self, digest):
        name = f"blobs/{digest.hash}/{digest.size_bytes}"
        data = b"".join(r.data for r in self.bytestream.Read(bytestream_pb2.ReadRequest(resource_name=name)))
        if len(data) != digest.size_bytes:
            raise RuntimeError(f"blob {digest.hash}: {len(data)} bytes, expected {digest.size_bytes}")
        return data

    def write(self, data):
        digest = digest_of(data)
        name = f"uploads/{uuid.uuid4()}/blobs/{digest.hash}/{digest.size_bytes}"

        def requests():
            offset = 0
            while True:
                chunk = data[offset : offset + CHUNK]
                last = offset + len(chunk) >= len(data)
                yield bytestream_pb2.WriteRequest(
                    resource_name=name if offset == 0 else "", write_offset=offset, data=chunk, finish_write=last
                )
                offset += len(chunk)
                if last:
                    return

        self.bytestream.Write(requests())
        return digest


def fetch_tree(cas, digest, path):
    """Writes the Directory `digest` and everything under it to `path`."""
    directory = re.Directory()
    directory.ParseFromString(cas.read(digest))
    os.makedirs(path, exist_ok=True)
    for f in directory.files:
        target = os.path.join(path, f.name)
        with open(target, "wb") as out:
            out.write(cas.read(f.digest))
        if f.is_executable:
            os.chmod(target, os.stat(target).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    for d in directory.directories:
        fetch_tree(cas, d.digest, os.path.join(path, d.name))
    for s in directory.symlinks:
        os.symlink(s.target, os.path.join(path, s.name))


def execute(cas, action):
    """Runs `action`; returns its ActionResult."""
    command = re.Command()
    command.ParseFromString(cas.read(action.command_digest))
    with tempfile.TemporaryDirectory(prefix="action-", dir=WORKDIR) as root:
        fetch_tree(cas, action.input_root_digest, root)
        cwd = os.path.join(root, command.working_directory)
        outputs = list(command.output_files) + list(command.output_paths)
        for out in outputs:
            os.makedirs(os.path.dirname(os.path.join(cwd, out)) or cwd, exist_ok=True)
        env = {v.name: v.value for v in command.environment_variables}
        program = command.arguments[0]
        if "/" in program and not os.path.isabs(program):
            program = os.path.join(cwd, program)
        run = subprocess.run([program] + list(command.arguments[1:]), cwd=cwd, env=env, capture_output=True)
        result = re.ActionResult(exit_code=run.returncode)
        result.stdout_digest.CopyFrom(cas.write(run.stdout))
        result.stderr_digest.CopyFrom(cas.write(run.stderr))
        for out in outputs:
            full = os.path.join(cwd, out)
            if os.path.isfile(full):
                with open(full, "rb") as f:
                    data = f.read()
                result.output_files.add(path=out, digest=cas.write(data), is_executable=os.access(full, os.X_OK))
        return result


def main(address):
    channel = grpc.insecure_channel(address, options=[("grpc.max_receive_message_length", 64 << 20)])
    bots = bots_pb2_grpc.BotsStub(channel)
    cas = Cas(channel)
    worker = worker_pb2.Worker(devices=[worker_pb2.Device(handle="kiln-test-worker")])
    session = bots.CreateBotSession(
        bots_pb2.CreateBotSessionRequest(
            parent="",
            bot_session=bots_pb2.BotSession(bot_id=f"kiln-test-{os.getpid()}", status=bots_pb2.OK, worker=worker),
        )
    )
    print(f"worker: session {session.name}", flush=True)
    while True:
        for lease in session.leases:
            if lease.state == bots_pb2.LeaseState.PENDING:
                lease.state = bots_pb2.LeaseState.ACTIVE
            elif lease.state == bots_pb2.LeaseState.ACTIVE and not lease.HasField("result"):
                if lease.payload.Is(re.Action.DESCRIPTOR):
                    action = re.Action()
                    lease.payload.Unpack(action)
                else:
                    digest = re.Digest()
                    lease.payload.Unpack(digest)
                    action = re.Action()
                    action.ParseFromString(cas.read(digest))
                result = execute(cas, action)
                print(f"worker: lease {lease.id} exit {result.exit_code}", flush=True)
                lease.result.Pack(result)
                lease.status.code = 0
                lease.state = bots_pb2.LeaseState.COMPLETED
        session = bots.UpdateBotSession(bots_pb2.UpdateBotSessionRequest(name=session.name, bot_session=session))
        # Completed leases are dropped once the server has them.
        kept = [l for l in session.leases if l.state != bots_pb2.LeaseState.COMPLETED]
        del session.leases[:]
        session.leases.extend(kept)
        if not kept:
            time.sleep(0.1)


if __name__ == "__main__":
    address, WORKDIR = sys.argv[1], sys.argv[2]
    main(address)

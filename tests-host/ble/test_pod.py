"""The foot pod against a watch that is not ours: `gaitclip pod` (the pod's own Bluetooth
code, trouble-host, over HCI) on one of Google Bumble's virtual controllers, a Bumble
central on another, both on one virtual link.

The central checks what a watch would: the advertising, the attribute table, the RSC
Measurement notifications of a real walk decoded from the RSCS 1.0 specification (not with
the pod's encoder), the SC Control Point's procedure and its errors, a disconnection and a
link loss, and an hour's soak.

Run by `tests-host/test-all.sh` in the venv it creates (`GAITCLIP` names the binary,
`GAITCLIP_DATASETS` the shared datasets).
"""

import asyncio
import contextlib
import json
import os
import signal
import socket
import struct
import tempfile
from pathlib import Path

import pytest
from bumble import att
from bumble.controller import Controller
from bumble.device import Device, Peer
from bumble.hci import Address, HCI_CONNECTION_TIMEOUT_ERROR
from bumble.host import Host
from bumble.link import LocalLink
from bumble.transport import open_transport
from bumble.transport.common import AsyncPipeSink

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
GAITCLIP = os.environ.get(
    "GAITCLIP", str(HERE.parent / "target" / "x86_64-unknown-linux-gnu" / "release" / "gaitclip")
)
DATASETS = Path(os.environ.get("GAITCLIP_DATASETS", str(ROOT.parent / "shared" / "datasets")))
DEMO = ROOT / "fixtures" / "demo_walk.csv"

RSC, BATTERY, DIS, GAP, GATT = 0x1814, 0x180F, 0x180A, 0x1800, 0x1801
RSC_MEASUREMENT, RSC_FEATURE, SENSOR_LOCATION, SC_CONTROL_POINT = 0x2A53, 0x2A54, 0x2A5D, 0x2A55
BATTERY_LEVEL = 0x2A19
MANUFACTURER, MODEL, FIRMWARE = 0x2A29, 0x2A24, 0x2A26

# What the pod's table lists (boards/common/src/rsc_gatt.rs, docs/bluetooth.md): nothing more.
TABLE = {
    GAP: {0x2A00, 0x2A01},
    GATT: set(),
    RSC: {RSC_MEASUREMENT, RSC_FEATURE, SENSOR_LOCATION, SC_CONTROL_POINT},
    BATTERY: {BATTERY_LEVEL},
    DIS: {MANUFACTURER, MODEL, FIRMWARE},
}


def in_ci():
    return os.environ.get("CI") == "true"


def need(path: Path):
    if not path.exists():
        if in_ci():
            pytest.fail(f"{path} is missing in CI")
        pytest.skip(f"{path} is not present")
    return path


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# --- the RSCS 1.0 specification, written out here (§3.1, §3.4) ----------------------------


def decode_measurement(b: bytes) -> dict:
    """RSC Measurement: flags (bit 0 stride length present, bit 1 total distance present,
    bit 2 running), speed uint16 in 1/256 m/s, cadence uint8 in 1/min, then the optional
    stride length uint16 in 1/100 m and total distance uint32 in 1/10 m."""
    flags = b[0]
    speed, cadence = struct.unpack_from("<HB", b, 1)
    out = {"speed_m_s": speed / 256, "cadence": cadence, "running": bool(flags & 4)}
    at = 4
    if flags & 1:
        (sl,) = struct.unpack_from("<H", b, at)
        out["stride_m"] = sl / 100
        at += 2
    if flags & 2:
        (td,) = struct.unpack_from("<I", b, at)
        out["total_m"] = td / 10
        at += 4
    assert at == len(b), f"{b.hex()}: {len(b)} bytes for flags {flags:#04x}"
    assert flags & ~0x07 == 0, f"reserved flag bits set: {flags:#04x}"
    return out


def ad_structures(data: bytes) -> dict:
    """Advertising data (Core Supplement §1): length, type, value, repeated."""
    out, at = {}, 0
    while at < len(data):
        n = data[at]
        if n == 0:
            break
        out[data[at + 1]] = data[at + 2 : at + 1 + n]
        at += 1 + n
    assert at == len(data), data.hex()
    return out


# --- the harness ----------------------------------------------------------------------------


class Pod:
    """`gaitclip pod` on a Bumble controller over TCP, and the lines it prints."""

    def __init__(self, link: LocalLink, trace: Path, *args: str):
        self.link, self.trace, self.args = link, trace, args
        self.strides, self.events, self.summary, self.stopped = [], [], None, None
        self.port = free_port()

    async def start(self):
        self.transport = await open_transport(f"tcp-server:127.0.0.1:{self.port}")
        self.controller = Controller(
            "pod", host_source=self.transport.source, host_sink=self.transport.sink, link=self.link
        )
        self.proc = await asyncio.create_subprocess_exec(
            GAITCLIP, "pod", "--hci", f"tcp:127.0.0.1:{self.port}", "--json", *self.args, str(self.trace),
            stdout=asyncio.subprocess.PIPE,
        )
        self.reader = asyncio.create_task(self._read())
        return self

    async def _read(self):
        while line := await self.proc.stdout.readline():
            v = json.loads(line)
            if "ble" in v:
                self.events.append(v["ble"])
            elif "summary" in v:
                self.summary = v["summary"]
            elif "pod_stopped" in v:
                self.stopped = v["pod_stopped"]
            else:
                self.strides.append(v)

    def count(self, kind):
        return sum(1 for e in self.events if e["event"] == kind)

    async def until(self, pred, timeout=30.0):
        async with asyncio.timeout(timeout):
            while not pred():
                await asyncio.sleep(0.02)

    def rss_kib(self):
        for l in Path(f"/proc/{self.proc.pid}/status").read_text().splitlines():
            if l.startswith("VmRSS:"):
                return int(l.split()[1])
        return 0

    async def stop(self):
        if self.proc.returncode is None:
            self.proc.send_signal(signal.SIGINT)
            code = await asyncio.wait_for(self.proc.wait(), 10)
            await self.reader
            assert code == 0, f"pod exited with {code}"
            assert self.stopped is not None, "no final counters after SIGINT"
        await self.transport.close()


class Watch:
    """A Bumble central on its own controller."""

    def __init__(self, link: LocalLink, n: int = 0):
        addr = f"F{n}:F0:F0:F0:F0:F0"
        self.controller = Controller(f"watch{n}", link=link, public_address=addr)
        self.device = Device(address=Address(addr), host=Host(self.controller, AsyncPipeSink(self.controller)))

    async def start(self):
        await self.device.power_on()
        return self

    async def find(self, active=True, timeout=10.0):
        found = asyncio.get_running_loop().create_future()

        def on_adv(adv):
            if ad_structures(adv.data_bytes).get(0x09) == b"gaitclip" and not found.done():
                found.set_result(adv)

        self.device.on("advertisement", on_adv)
        await self.device.start_scanning(active=active)
        try:
            return await asyncio.wait_for(found, timeout)
        finally:
            await self.device.stop_scanning()
            self.device.remove_listener("advertisement", on_adv)

    async def connect(self):
        adv = await self.find()
        self.connection = await self.device.connect(adv.address)
        self.peer = Peer(self.connection)
        await self.peer.discover_services()
        for s in self.peer.services:
            await s.discover_characteristics()
        return self

    def char(self, service, uuid):
        (s,) = [s for s in self.peer.services if s.uuid.to_bytes() == struct.pack("<H", service)]
        (c,) = [c for c in s.characteristics if c.uuid.to_bytes() == struct.pack("<H", uuid)]
        return c

    async def subscribe(self, into: list):
        m = self.char(RSC, RSC_MEASUREMENT)
        await m.discover_descriptors()
        await self.peer.subscribe(m, lambda v: into.append(decode_measurement(bytes(v))))


@contextlib.asynccontextmanager
async def session(trace: Path, *args: str, watches: int = 1):
    link = LocalLink()
    pod = await Pod(link, trace, *args).start()
    ws = [await Watch(link, n).start() for n in range(watches)]
    try:
        yield pod, ws
    finally:
        await pod.stop()


def run(coro):
    asyncio.run(coro)


# --- the tests ------------------------------------------------------------------------------


def test_advertising_is_what_a_watch_looks_for():
    async def go():
        async with session(DEMO) as (pod, (watch,)):
            for active in (True, False):
                adv = await watch.find(active=active)
                d = adv.data_bytes
                assert len(d) <= 31, len(d)
                ad = ad_structures(d)
                assert ad[0x01] == bytes([0x06]), "flags: LE general discoverable, no BR/EDR"
                assert ad[0x09] == b"gaitclip"
                uuids = {struct.unpack_from("<H", ad[0x03], i)[0] for i in range(0, len(ad[0x03]), 2)}
                assert {RSC, BATTERY} <= uuids, uuids
                assert struct.unpack("<H", ad[0x19])[0] == 0x0442, "appearance: on-shoe running/walking sensor"
                assert adv.is_connectable
            await pod.until(lambda: pod.count("advertising") >= 1)

    run(go())


def test_the_table_is_the_documented_one_and_reads_back():
    async def go():
        async with session(DEMO, "--battery-percent", "87") as (pod, (watch,)):
            await watch.connect()
            got = {
                struct.unpack("<H", s.uuid.to_bytes())[0]: {
                    struct.unpack("<H", c.uuid.to_bytes())[0] for c in s.characteristics
                }
                for s in watch.peer.services
            }
            assert got == TABLE, got
            feature = await watch.char(RSC, RSC_FEATURE).read_value()
            assert struct.unpack("<H", feature)[0] == 0x0007, "stride length, total distance, walking/running"
            assert await watch.char(RSC, SENSOR_LOCATION).read_value() == bytes([1]), "top of shoe"
            assert await watch.char(BATTERY, BATTERY_LEVEL).read_value() == bytes([87])
            assert await watch.char(DIS, MANUFACTURER).read_value() == b"gaitclip"
            assert await watch.char(DIS, MODEL).read_value() == b"gaitclip nRF52840 + MPU6050"
            fw = (await watch.char(DIS, FIRMWARE).read_value()).decode()
            assert fw.count(".") == 2, fw
            await pod.until(lambda: pod.count("connected") == 1)

    run(go())


def check_notifications(strides, notes):
    """Every stride notified once, in order, each field equal to the stride within the
    field's resolution; the running total the sum of the lengths."""
    walked = [n for n in notes if "stride_m" in n]
    assert len(walked) == len(strides), (len(walked), len(strides))
    total = 0.0
    for s, n in zip(strides, walked):
        assert abs(n["speed_m_s"] - s["gait_velocity_m_s"]) <= 1 / 256 + 1e-9, (s, n)
        # RSCS's cadence: contacts of the sensor's foot per minute, half the steps of both.
        assert n["cadence"] == min((s["cadence_spm"] + 1) // 2, 255), (s, n)
        assert abs(n["stride_m"] - s["length_m"]) <= 0.005 + 1e-9, (s, n)
        assert n["running"] == (s["gait"] == "running"), (s, n)
        total += s["length_m"]
        assert abs(n["total_m"] - int(round(total * 1000)) // 100 / 10) < 1e-9, (total, n)
    return walked


def test_a_real_walk_is_notified_stride_by_stride_as_the_replay_measures_it():
    trace = need(DATASETS / "gaitmap_walk" / "left.csv")

    async def go():
        notes = []
        async with session(trace, "--wait-for-central", "--speed", "20") as (pod, (watch,)):
            await watch.connect()
            await watch.subscribe(notes)
            await pod.until(lambda: pod.summary is not None, 60)
            await asyncio.sleep(0.5)
            strides = list(pod.strides)
            check_notifications(strides, notes)
            assert pod.count("subscribed") == 1
            # Standing after the walk: speed 0, no stride length, about once a second.
            before = len(notes)
            await asyncio.sleep(4.2)
            standing = notes[before:]
            assert 2 <= len(standing) <= 5, standing
            assert all(n["speed_m_s"] == 0 and "stride_m" not in n for n in standing), standing
        # The pod's strides are `gaitclip replay --json`'s, field for field.
        out = await asyncio.create_subprocess_exec(GAITCLIP, "replay", "--json", str(trace), stdout=asyncio.subprocess.PIPE)
        lines = [json.loads(l) for l in (await out.communicate())[0].splitlines()]
        assert [l for l in lines if "summary" not in l] == strides

    run(go())


def test_the_control_point_follows_the_rscs_procedure():
    async def go():
        notes = []
        async with session(DEMO, "--wait-for-central", "--speed", "4") as (pod, (watch,)):
            await watch.connect()
            cp = watch.char(RSC, SC_CONTROL_POINT)
            await cp.discover_descriptors()
            # Indications off: 0x81 (CCCD improperly configured).
            with pytest.raises(att.ATT_Error) as e:
                await cp.write_value(bytes([0x01, 0, 0, 0, 0]), with_response=True)
            assert e.value.error_code == 0x81
            indications = asyncio.Queue()
            await watch.peer.subscribe(cp, lambda v: indications.put_nowait(bytes(v)), prefer_notify=False)
            await watch.subscribe(notes)
            await pod.until(lambda: len([n for n in notes if "stride_m" in n]) >= 2, 60)
            # Set Cumulative Value 1234.5 m: indicated as success, the next total continues.
            await cp.write_value(bytes([0x01]) + struct.pack("<I", 12345), with_response=True)
            assert await asyncio.wait_for(indications.get(), 5) == bytes([0x10, 0x01, 0x01])
            k = len(notes)
            await pod.until(lambda: any("stride_m" in n for n in notes[k:]), 60)
            first = next(n for n in notes[k:] if "stride_m" in n)
            assert 1234.5 < first["total_m"] < 1234.5 + 2.0, first
            # An op code the pod does not support: "Op Code not supported" (0x02).
            await cp.write_value(bytes([0x02]), with_response=True)
            assert await asyncio.wait_for(indications.get(), 5) == bytes([0x10, 0x02, 0x02])
            # A Set Cumulative Value with a short parameter: "Invalid Parameter" (0x03).
            await cp.write_value(bytes([0x01, 0x07]), with_response=True)
            assert await asyncio.wait_for(indications.get(), 5) == bytes([0x10, 0x01, 0x03])
            # Empty: ATT 0x0D (invalid attribute value length). Over-long (6 bytes, the
            # characteristic holds 5): refused by the attribute server, also 0x0D.
            for bad in (b"", bytes(6)):
                with pytest.raises(att.ATT_Error) as e:
                    await cp.write_value(bad, with_response=True)
                assert e.value.error_code == 0x0D, (bad, e.value)
            # A second write while the first one's indication is not confirmed: 0x80.
            client = watch.peer.gatt_client
            held = []
            real = client.send_confirmation
            client.send_confirmation = held.append
            await cp.write_value(bytes([0x01]) + struct.pack("<I", 0), with_response=True)
            assert await asyncio.wait_for(indications.get(), 5) == bytes([0x10, 0x01, 0x01])
            with pytest.raises(att.ATT_Error) as e:
                await cp.write_value(bytes([0x02]), with_response=True)
            assert e.value.error_code == 0x80
            client.send_confirmation = real
            for c in held:
                real(c)
            await pod.until(lambda: pod.count("indication_done") >= 4)
            # It keeps serving after every refusal.
            await cp.write_value(bytes([0x02]), with_response=True)
            assert await asyncio.wait_for(indications.get(), 5) == bytes([0x10, 0x02, 0x02])
            assert await watch.char(BATTERY, BATTERY_LEVEL).read_value() == bytes([100])
            k = len(notes)
            await pod.until(lambda: len(notes) > k, 60)

    run(go())


def test_a_disconnection_and_a_link_loss_lose_nothing_and_replay_nothing():
    trace = need(DATASETS / "gaitmap_walk" / "left.csv")

    async def go():
        first, second, third = [], [], []
        async with session(trace, "--wait-for-central", "--speed", "10", watches=2) as (pod, (w1, w2)):
            await w1.connect()
            await w1.subscribe(first)
            await pod.until(lambda: len(pod.strides) >= 8, 60)
            await w1.connection.disconnect()
            await pod.until(lambda: pod.count("disconnected") == 1)
            missed_from = len(pod.strides)
            await pod.until(lambda: len(pod.strides) >= missed_from + 3, 60)
            # The same watch again: the total carried on, no stale measurement replayed.
            await w1.connect()
            await w1.subscribe(second)
            await pod.until(lambda: any("stride_m" in n for n in second), 60)
            n0 = next(n for n in second if "stride_m" in n)
            walked = [n for n in first if "stride_m" in n]
            assert n0["total_m"] > walked[-1]["total_m"] + 3 * 0.5, (walked[-1], n0)
            # It is a stride walked after the reconnection, and its total counts every stride
            # up to it, those walked while nobody listened included.
            cum, totals = 0, []
            for s in pod.strides:
                cum += round(s["length_m"] * 1000)
                totals.append(cum // 100 / 10)
            later = [
                i
                for i in range(missed_from, len(pod.strides))
                if abs(totals[i] - n0["total_m"]) < 1e-9
                and abs(pod.strides[i]["length_m"] - n0["stride_m"]) <= 0.005 + 1e-9
            ]
            assert later, (n0, pod.strides[missed_from:], totals[missed_from:])
            # A link loss: the watch's controller leaves the link without a disconnection.
            # Bumble's virtual link has no supervision timeout, so the harness plays the
            # air's part: the pod's controller reports the connection timed out (0x08).
            pod.link.remove_controller(w1.controller)
            (conn,) = pod.controller.le_connections.values()
            pod.controller.on_le_disconnected(conn, HCI_CONNECTION_TIMEOUT_ERROR)
            await pod.until(lambda: pod.count("disconnected") == 2)
            assert [e["reason"] for e in pod.events if e["event"] == "disconnected"][-1] == 0x08
            await pod.until(lambda: pod.count("advertising") >= 3)
            await w2.connect()
            await w2.subscribe(third)
            await pod.until(lambda: pod.summary is not None, 60)
            await pod.until(lambda: any("stride_m" in n for n in third) or pod.summary, 10)
            assert pod.count("connected") == 3

    run(go())


def soak_trace(minutes: float) -> Path:
    """Real walks end to end (the `pyshoe_vicon` trials, all at 200 Hz, over and over),
    `minutes` long, in a temporary file (never in the repository)."""
    sources = sorted(need(DATASETS / "pyshoe_vicon").glob("20*[0-9].csv"))
    out = Path(tempfile.mkdtemp()) / "soak.csv"
    t_end, rows = 0.0, ["t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z"]
    while t_end < minutes * 60:
        for src in sources:
            lines = src.read_text().splitlines()
            head = lines[0].split(",")
            ix = [head.index(c) for c in rows[0].split(",")]
            t0 = None
            for l in lines[1:]:
                v = l.split(",")
                t = float(v[ix[0]])
                t0 = t if t0 is None else t0
                rows.append(",".join([f"{t_end + t - t0 + 0.005:.6f}"] + [v[i] for i in ix[1:]]))
            t_end = float(rows[-1].split(",")[0]) + 0.5
            if t_end >= minutes * 60:
                break
    out.write_text("\n".join(rows) + "\n")
    return out


def test_an_hour_at_thirty_times_real_time_notifies_every_stride_once():
    trace = soak_trace(60)

    async def go():
        notes = []
        async with session(trace, "--wait-for-central", "--speed", "30", "--rate", "200") as (pod, (watch,)):
            await watch.connect()
            await watch.subscribe(notes)
            await pod.until(lambda: len(pod.strides) >= 100, 60)
            rss0 = pod.rss_kib()
            await pod.until(lambda: pod.summary is not None, 60 * 60 / 30 + 120)
            rss1 = pod.rss_kib()
            await asyncio.sleep(0.5)
            walked = check_notifications(pod.strides, notes)
            print(f"soak: {len(walked)} strides notified, RSS {rss0} -> {rss1} KiB")
            assert len(walked) > 1500
            assert rss1 - rss0 < 2048, (rss0, rss1)

    run(go())


# --- the documented surface ---------------------------------------------------------------

DOC = ROOT / "docs" / "bluetooth.md"
OPEN, CLOSE = "<!-- generated: pytest tests-host/ble/test_pod.py -->", "<!-- end generated -->"


def surface_markdown(adv: bytes, peer: Peer, notes_raw: list, strides: list) -> str:
    names = {GAP: "Generic Access", GATT: "Generic Attribute", RSC: "Running Speed and Cadence",
             BATTERY: "Battery", DIS: "Device Information", 0x2A00: "Device Name", 0x2A01: "Appearance",
             RSC_MEASUREMENT: "RSC Measurement", RSC_FEATURE: "RSC Feature", SENSOR_LOCATION: "Sensor Location",
             SC_CONTROL_POINT: "SC Control Point", BATTERY_LEVEL: "Battery Level",
             MANUFACTURER: "Manufacturer Name String", MODEL: "Model Number String", FIRMWARE: "Firmware Revision String"}
    out = [f"Advertising data ({len(adv)} of 31 bytes): `{adv.hex(' ')}`", ""]
    for t, v in ad_structures(adv).items():
        out.append(f"- AD type 0x{t:02X}: `{v.hex(' ')}`")
    out += ["", "| handle | attribute | UUID | properties |", "|---|---|---|---|"]
    for s in peer.services:
        u = struct.unpack("<H", s.uuid.to_bytes())[0]
        out.append(f"| 0x{s.handle:04X} | service: {names.get(u, '?')} | 0x{u:04X} | |")
        for c in s.characteristics:
            cu = struct.unpack("<H", c.uuid.to_bytes())[0]
            out.append(f"| 0x{c.handle:04X} | {names.get(cu, '?')} | 0x{cu:04X} | {str(c.properties).replace('|', ', ')} |")
            for d in c.descriptors:
                du = struct.unpack("<H", d.type.to_bytes())[0]
                out.append(f"| 0x{d.handle:04X} | descriptor | 0x{du:04X} | |")
    out += ["", "The first strides of `gaitmap_walk/left` as a watch receives them (decoded by the test's own",
            "RSCS decoder) beside the stride the replay measured:", "",
            "| stride | notification | speed m/s | cadence 1/min | stride m | total m | running | replay: length m, velocity m/s, steps/min |",
            "|---|---|---|---|---|---|---|---|"]
    walked = [(raw, decode_measurement(raw)) for raw in notes_raw if decode_measurement(raw).get("stride_m") is not None]
    for (raw, n), s in list(zip(walked, strides))[:8]:
        out.append(f"| {s['index']} | `{raw.hex(' ')}` | {n['speed_m_s']:.3f} | {n['cadence']} | {n['stride_m']:.2f} | "
                   f"{n['total_m']:.1f} | {'yes' if n['running'] else 'no'} | {s['length_m']:.3f}, {s['gait_velocity_m_s']:.3f}, {s['cadence_spm']} |")
    return "\n".join(out) + "\n"


def test_the_documented_surface_is_what_a_watch_sees():
    trace = need(DATASETS / "gaitmap_walk" / "left.csv")

    async def go():
        raw = []
        async with session(trace, "--wait-for-central", "--speed", "40") as (pod, (watch,)):
            adv = await watch.find()
            watch.connection = await watch.device.connect(adv.address)
            watch.peer = Peer(watch.connection)
            await watch.peer.discover_services()
            for s in watch.peer.services:
                await s.discover_characteristics()
                for c in s.characteristics:
                    await c.discover_descriptors()
            m = watch.char(RSC, RSC_MEASUREMENT)
            await watch.peer.subscribe(m, lambda v: raw.append(bytes(v)))
            await pod.until(lambda: len(pod.strides) >= 10, 60)
            await asyncio.sleep(0.3)
            return surface_markdown(adv.data_bytes, watch.peer, raw, pod.strides)

    md = asyncio.run(go())
    text = DOC.read_text()
    start = text.index(OPEN) + len(OPEN) + 1
    end = text.index(CLOSE, start)
    if os.environ.get("GAITCLIP_WRITE_DOCS") == "1":
        DOC.write_text(text[:start] + md + text[end:])
        return
    assert text[start:end] == md, (
        "docs/bluetooth.md is stale: run `GAITCLIP_WRITE_DOCS=1 pytest tests-host/ble -k surface` in its venv"
    )

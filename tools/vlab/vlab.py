#!/usr/bin/env python3
"""Basalt's virtual lab: a stock Debian kernel under qemu with real drivers (vivid, dummy_hcd
with configfs HID gadgets, uhid, virtio-gpu, uvcvideo with the lab's own UVC camera plugged in
through qemu's usb-redir), the host's root mounted read-only, running Basalt's test binaries
against it.

    vlab.py build [--force]            build (or find cached) the kernel and initramfs
    vlab.py run [opts] -- PROG ARGS    run one program inside the lab; its output and exit status
    vlab.py batch --jobs F --results D run the jobs of a JSON file in one boot (for ctest)
    vlab.py result --results D --job J [--case C]   a job's (or one gtest case's) result
    vlab.py shell                      an interactive shell inside the lab
    vlab.py check                      says whether the lab can run here, and why not

Exit status: what the program exited with (run), 0 when the lab ran (batch), 77 when the lab
cannot run on this machine (the reason is printed as "SKIPPED: ..."), 125 when the lab itself
failed (did not boot, timed out, the kernel stopped): the tail of the console log is printed.

Everything comes from Debian packages: the kernel is the one linux-image-amd64 depends on
(resolved with apt-cache, downloaded with apt-get download), busybox-static, qemu-system-x86,
cpio and kmod. Built files are cached in $BASALT_VLAB_CACHE (default ~/.cache/basalt/vlab),
keyed by the kernel version and the content of the files that go into the initramfs.
"""
import argparse
import fcntl
import glob
import gzip
import hashlib
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
# Host folders the guest covers with tmpfs (guest/init), where programs write.
GUEST_TMPFS = ("/tmp", "/run", "/var/tmp", "/root")
EXIT_SKIP = 77
EXIT_LAB_FAILED = 125
# The kernel package unpacked is about 400 MB, the .deb 70 MB.
NEEDED_MB = int(os.environ.get("BASALT_VLAB_MIN_FREE_MB", "700"))


class LabUnavailable(Exception):
    """The lab cannot run on this machine (missing tool, package, disk): tests skip."""


class LabFailed(Exception):
    """The lab ran and broke (no boot, time-out, kernel stopped): tests fail."""


def say(msg):
    print(f"vlab: {msg}", file=sys.stderr, flush=True)


def cache_dir():
    base = os.environ.get("BASALT_VLAB_CACHE")
    if not base:
        base = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "basalt", "vlab")
    os.makedirs(base, exist_ok=True)
    return base


def free_mb(path):
    st = os.statvfs(path)
    return st.f_bavail * st.f_frsize // (1024 * 1024)


def tool(name, package):
    path = shutil.which(name)
    if not path:
        for d in ("/usr/sbin", "/sbin", "/usr/bin", "/bin"):
            if os.access(os.path.join(d, name), os.X_OK):
                return os.path.join(d, name)
        raise LabUnavailable(f"{name} is not installed (Debian package {package}): run scripts/setup.sh --test")
    return path


def qemu_binary():
    return tool("qemu-system-x86_64", "qemu-system-x86")


def static_busybox():
    path = tool("busybox", "busybox-static")
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    # A dynamically linked busybox (package busybox) names its interpreter; the static one does not.
    if b"/lib64/ld-linux" in head or b"ld-linux-x86-64" in head:
        raise LabUnavailable(f"{path} is dynamically linked: install busybox-static (scripts/setup.sh --test)")
    return path


def run_quiet(argv, what, **kw):
    p = subprocess.run(argv, capture_output=True, text=True, check=False, **kw)
    if p.returncode != 0:
        tail = "\n".join((p.stderr or p.stdout).strip().splitlines()[-5:])
        raise LabUnavailable(f"{what} failed ({' '.join(argv)}):\n{tail}")
    return p.stdout


# ---- the kernel ---------------------------------------------------------------------------


def resolve_kernel_package():
    """The linux-image-X package that linux-image-amd64 depends on, by apt-cache."""
    out = subprocess.run(["apt-cache", "depends", "linux-image-amd64"], capture_output=True, text=True, check=False)
    for line in out.stdout.splitlines():
        m = re.match(r"\s*Depends:\s*(linux-image-\S+)", line)
        if m:
            return m.group(1)
    return None


def kernel_deb(cache):
    """Path of the kernel .deb: $BASALT_VLAB_KERNEL_DEB, the cached one for the resolved
    package, a fresh download, or (offline) the newest cached one."""
    override = os.environ.get("BASALT_VLAB_KERNEL_DEB")
    if override:
        if not os.path.isfile(override):
            raise LabUnavailable(f"BASALT_VLAB_KERNEL_DEB={override} does not exist")
        return override
    debs = os.path.join(cache, "debs")
    os.makedirs(debs, exist_ok=True)
    package = os.environ.get("BASALT_VLAB_KERNEL_PACKAGE") or resolve_kernel_package()
    cached = sorted(glob.glob(os.path.join(debs, "linux-image-*.deb")), key=os.path.getmtime)
    if package is None:
        if cached:
            say(f"cannot resolve linux-image-amd64 with apt-cache; using the cached {os.path.basename(cached[-1])}")
            return cached[-1]
        raise LabUnavailable(
            "missing kernel package: apt-cache cannot resolve linux-image-amd64 (run apt-get update; "
            "or point BASALT_VLAB_KERNEL_DEB at a Debian linux-image .deb)")
    for deb in cached:
        if os.path.basename(deb).startswith(package + "_"):
            return deb
    if free_mb(debs) < NEEDED_MB:
        raise LabUnavailable(f"no free disk: the lab needs about {NEEDED_MB} MB in {debs}, "
                             f"{free_mb(debs)} MB are free (free some, or set BASALT_VLAB_CACHE)")
    say(f"downloading the kernel package {package} (apt-get download)")
    with tempfile.TemporaryDirectory(dir=debs) as tmp:
        p = subprocess.run(["apt-get", "download", "-o", "APT::Sandbox::User=root", package], cwd=tmp,
                           capture_output=True, text=True, check=False)
        got = glob.glob(os.path.join(tmp, "*.deb"))
        if p.returncode != 0 or not got:
            tail = "\n".join(p.stderr.strip().splitlines()[-4:])
            raise LabUnavailable(f"missing kernel package: apt-get download {package} failed:\n{tail}\n"
                                 "(run apt-get update, check the network, or set BASALT_VLAB_KERNEL_DEB)")
        dest = os.path.join(debs, os.path.basename(got[0]))
        os.replace(got[0], dest)
    return dest


def read_module_list():
    wanted = []
    with open(os.path.join(HERE, "modules.txt"), encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                wanted.append((line.rstrip("?"), line.endswith("?")))
    return wanted


def initramfs_inputs():
    """Files whose content decides the initramfs (the cache key)."""
    return [os.path.join(HERE, "guest", "init"), os.path.join(HERE, "modules.txt"), os.path.abspath(__file__)]


def lab_key(deb):
    h = hashlib.sha256()
    h.update(os.path.basename(deb).encode())
    h.update(str(os.path.getsize(deb)).encode())
    for path in initramfs_inputs():
        with open(path, "rb") as f:
            h.update(f.read())
    with open(static_busybox(), "rb") as f:
        h.update(hashlib.sha256(f.read()).digest())
    return h.hexdigest()[:16]


def build(force=False):
    """Returns the folder holding vmlinuz, initrd.gz and lab.json, building it when needed."""
    for name, pkg in (("cpio", "cpio"), ("depmod", "kmod"), ("modprobe", "kmod"), ("dpkg-deb", "dpkg")):
        tool(name, pkg)
    qemu_binary()
    busybox = static_busybox()
    cache = cache_dir()
    with open(os.path.join(cache, "lock"), "w", encoding="utf-8") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        deb = kernel_deb(cache)
        lab = os.path.join(cache, "lab-" + lab_key(deb))
        if os.path.isfile(os.path.join(lab, "lab.json")) and not force:
            os.utime(os.path.join(lab, "lab.json"))  # in use: kept by prune_labs
            return lab
        if free_mb(cache) < NEEDED_MB:
            raise LabUnavailable(f"no free disk: building the lab needs about {NEEDED_MB} MB in {cache}, "
                                 f"{free_mb(cache)} MB are free (free some, or set BASALT_VLAB_CACHE)")
        say(f"building the lab from {os.path.basename(deb)}")
        started = time.monotonic()
        with tempfile.TemporaryDirectory(dir=cache) as tmp:
            tree = os.path.join(tmp, "kernel")
            run_quiet(["dpkg-deb", "-x", deb, tree], f"unpacking {deb}")
            versions = os.listdir(os.path.join(tree, "lib", "modules"))
            vmlinuz = glob.glob(os.path.join(tree, "boot", "vmlinuz-*"))
            if len(versions) != 1 or not vmlinuz:
                raise LabUnavailable(f"{deb} is not a kernel image package (no boot/vmlinuz-* and lib/modules/VERSION)")
            version = versions[0]
            run_quiet(["depmod", "-b", tree, version], "depmod on the unpacked kernel")
            root = os.path.join(tmp, "initramfs")
            modules = closure(tree, version, root)
            for d in ("bin", "dev", "proc", "sys", "host", "tmp", "run"):
                os.makedirs(os.path.join(root, d), exist_ok=True)
            shutil.copy2(busybox, os.path.join(root, "bin", "busybox"))
            shutil.copy2(os.path.join(HERE, "guest", "init"), os.path.join(root, "init"))
            os.chmod(os.path.join(root, "init"), 0o755)
            out = os.path.join(tmp, "lab")
            os.makedirs(out)
            shutil.copy2(vmlinuz[0], os.path.join(out, "vmlinuz"))
            make_cpio(root, os.path.join(out, "initrd.gz"))
            with open(os.path.join(out, "lab.json"), "w", encoding="utf-8") as f:
                json.dump({"kernel": version, "deb": os.path.basename(deb), "modules": modules}, f, indent=1)
            if os.path.isdir(lab):
                shutil.rmtree(lab)
            os.replace(out, lab)
        prune_labs(cache, lab)
        say(f"lab built in {time.monotonic() - started:.1f} s: {lab}")
        return lab


def prune_labs(cache, keep, unused_days=3):
    """Removes labs not used for `unused_days` (12 MB each). Labs of other inputs stay for a
    while: checkouts of different branches share the cache, and deleting the lab another one
    is about to boot would make each rebuild the other's."""
    for old in glob.glob(os.path.join(cache, "lab-*")):
        stamp = os.path.join(old, "lab.json")
        try:
            idle = time.time() - os.path.getmtime(stamp)
        except OSError:
            idle = float("inf")  # a half-built lab left by a killed build
        if old != keep and idle > unused_days * 86400:
            shutil.rmtree(old, ignore_errors=True)


def closure(tree, version, root):
    """Copies the wanted modules and their dependencies into root/lib/modules/VERSION and runs
    depmod there, so that busybox modprobe finds them. Returns the module names."""
    src = os.path.join(tree, "lib", "modules", version)
    dst = os.path.join(root, "lib", "modules", version)
    os.makedirs(dst)
    files = set()
    names = []
    for name, optional in read_module_list():
        p = subprocess.run(["modprobe", "-d", tree, "-S", version, "--show-depends", name], capture_output=True,
                           text=True, check=False)
        if p.returncode != 0:
            if optional:
                say(f"optional module {name} is not in this kernel; the lab goes on without it")
                continue
            raise LabUnavailable(f"the kernel {version} has no module {name}: {p.stderr.strip()}")
        for line in p.stdout.splitlines():
            parts = line.split()
            if parts and parts[0] == "insmod":
                files.add(parts[1])
        names.append(name)
    for path in sorted(files):
        rel = os.path.relpath(path, src)
        target = os.path.join(dst, rel)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        if path.endswith(".xz") or path.endswith(".zst"):
            # busybox modprobe loads plain .ko files only; depmod below finds them by the new name.
            cmd = ["xz", "-dc", path] if path.endswith(".xz") else ["zstd", "-dc", path]
            with open(target.rsplit(".", 1)[0], "wb") as f:
                subprocess.run(cmd, stdout=f, check=True)
        else:
            shutil.copy2(path, target)
    for meta in ("modules.order", "modules.builtin", "modules.builtin.modinfo"):
        if os.path.exists(os.path.join(src, meta)):
            shutil.copy2(os.path.join(src, meta), dst)
    run_quiet(["depmod", "-b", root, version], "depmod on the initramfs")
    return names


def make_cpio(root, out):
    listing = []
    for d, dirs, fnames in os.walk(root):
        dirs.sort()
        for n in sorted(dirs + fnames):
            listing.append(os.path.relpath(os.path.join(d, n), root))
    p = subprocess.run(["cpio", "-o", "-H", "newc", "--quiet", "-R", "0:0"], input=("\n".join(listing) + "\n").encode(),
                       cwd=root, capture_output=True, check=False, text=False)
    if p.returncode != 0:
        raise LabUnavailable(f"cpio failed: {p.stderr.decode(errors='replace')}")
    with gzip.open(out, "wb", compresslevel=1) as f:
        f.write(p.stdout)


# ---- running ------------------------------------------------------------------------------


def default_build_dir():
    d = os.path.join(SOURCE, "build")
    return d if os.path.isdir(d) else None


def tools_dir(build_dir):
    if build_dir and os.path.exists(os.path.join(build_dir, "tools", "vlab", "basalt-vlab-hid-replay")):
        return os.path.join(build_dir, "tools", "vlab")
    return ""


class HostCamera:
    """The lab's webcam: basalt-vlab-uvc-camera runs here, on the host, and qemu's usb-redir
    device plugs it into the guest's emulated xHCI (qemu-xhci), where uvcvideo binds it. The
    guest unplugs and replugs it by writing "unplug" or "plug" to RESULTS/uvc-camera.request
    (gadget-ctl does); the camera says its state in uvc-camera.request.state."""

    def __init__(self, build_dir):
        self.program = os.path.join(build_dir, "tools", "vlab", "basalt-vlab-uvc-camera") if build_dir else None
        self.missing = None
        if not self.program or not os.access(self.program, os.X_OK):
            self.missing = (f"the camera program {self.program} is not built (cmake --build the tree)" if self.program
                            else "no build tree, so no camera program (basalt-vlab-uvc-camera)")
            self.program = None
        # A short folder of its own for the socket (a UNIX socket path has at most 107 bytes).
        self.folder = tempfile.mkdtemp(prefix="basalt-vlab-")
        self.socket = os.path.join(self.folder, "uvc.sock")
        self.proc = None

    def conf(self):
        if self.program:
            return "BASALT_VLAB_UVC_CAMERA=usbredir\n"
        return f"BASALT_VLAB_UVC_CAMERA=\nBASALT_VLAB_UVC_CAMERA_MISSING={shlex.quote(self.missing)}\n"

    def qemu_args(self):
        if not self.program:
            return []
        return ["-chardev", f"socket,id=uvccam,path={self.socket},server=on,wait=off",
                "-device", "usb-redir,chardev=uvccam,id=uvccam,bus=xhci.0"]

    def start(self, results):
        """Starts the camera once qemu runs (it waits for qemu's socket)."""
        if not self.program:
            return
        with open(os.path.join(results, "uvc-camera.log"), "w", encoding="utf-8") as log:
            self.proc = subprocess.Popen([self.program, "--usbredir", self.socket, "--connect-timeout", "60",
                                          "--control", os.path.join(results, "uvc-camera.request")],
                                         stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                         start_new_session=True)

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        shutil.rmtree(self.folder, ignore_errors=True)


def check_path(path, what):
    if re.search(r"[\s,:'\"\\]", path):
        raise LabUnavailable(f"{what} {path!r} has a space, comma, colon or quote; the lab cannot share it")


def console_tail(path, lines=40):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
    except OSError:
        return "(no console log)"
    text = text.replace("\r", "")
    return "\n".join(text.splitlines()[-lines:]) or "(the console log is empty)"


def qemu_argv(lab, results, shares, mode, camera=None):
    cmdline = ["console=ttyS0", "quiet", "loglevel=4", "panic=-1", "oops=panic", f"basalt.mode={mode}",
               f"basalt.lab={os.path.join(HERE, 'guest', 'lab.sh')}", f"basalt.results={results}"]
    argv = [qemu_binary(), "-accel", "tcg", "-m", os.environ.get("BASALT_VLAB_MEMORY", "1024"), "-smp", "2",
            "-nodefaults", "-no-user-config", "-no-reboot", "-display", "none",
            "-kernel", os.path.join(lab, "vmlinuz"), "-initrd", os.path.join(lab, "initrd.gz"),
            "-vga", "none", "-device", "virtio-gpu-pci", "-device", "qemu-xhci,id=xhci",
            "-virtfs", "local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap"]
    if camera:
        argv += camera.qemu_args()
    rw = []
    for i, path in enumerate(shares):
        argv += ["-virtfs", f"local,path={path},mount_tag=rw{i},security_model=none,multidevs=remap"]
        rw.append(f"rw{i}:{path}")
    if rw:
        cmdline.append("basalt.rw=" + ",".join(rw))
    if mode == "shell":
        argv += ["-serial", "mon:stdio"]
    else:
        argv += ["-serial", f"file:{os.path.join(results, 'console.log')}"]
    argv += ["-append", " ".join(cmdline)]
    return argv


def prepare(results, build_dir):
    """Makes the results folder, decides the writable shares and the host-side camera."""
    results = os.path.abspath(results)
    os.makedirs(results, exist_ok=True)
    for name in os.listdir(results):
        p = os.path.join(results, name)
        if os.path.isdir(p):
            shutil.rmtree(p)
        else:
            os.unlink(p)
    shares = []
    if build_dir:
        build_dir = os.path.abspath(build_dir)
        shares.append(build_dir)
    if not any(results == s or results.startswith(s + os.sep) for s in shares):
        shares.append(results)
    # The guest mounts empty tmpfs over some host folders (programs write there): a checkout in
    # one of them (a clone in /tmp, say) is shared on its own, or the lab would not see its
    # scripts. First, so that the build folder's share inside it is mounted over it.
    if any(SOURCE.startswith(d + os.sep) for d in GUEST_TMPFS):
        shares.insert(0, SOURCE)
    for p in shares + [results, HERE]:
        check_path(p, "the path")
    camera = HostCamera(build_dir)
    with open(os.path.join(results, "lab.conf"), "w", encoding="utf-8") as f:
        f.write(f"BASALT_VLAB_SRC={SOURCE}\nBASALT_VLAB_TOOLS={tools_dir(build_dir)}\n" + camera.conf())
    return results, shares, camera


def write_jobs(results, jobs):
    """jobs: [{name, argv, timeout, cwd, env}] -> results/jobs and results/NAME.sh"""
    with open(os.path.join(results, "jobs"), "w", encoding="utf-8") as f:
        for job in jobs:
            if not re.fullmatch(r"[A-Za-z0-9_.+-]+", job["name"]):
                raise LabFailed(f"job name {job['name']!r} must be letters, digits and ._+-")
            f.write(f"{job['name']} {int(job.get('timeout', 300))}\n")
            lines = ["set -e", f"cd {shlex.quote(job.get('cwd') or SOURCE)}"]
            for k, v in sorted((job.get("env") or {}).items()):
                lines.append(f"export {k}={shlex.quote(str(v))}")
            lines.append("exec " + shlex.join(job["argv"]))
            with open(os.path.join(results, job["name"] + ".sh"), "w", encoding="utf-8") as s:
                s.write("\n".join(lines) + "\n")


def boot(results, shares, jobs, boot_timeout, camera):
    """Boots the lab, runs the jobs, waits for power-off. Raises LabFailed with the console tail."""
    try:
        lab = build()
    except (LabUnavailable, LabFailed):
        camera.stop()
        raise
    budget = boot_timeout + sum(int(j.get("timeout", 300)) + 10 for j in jobs) + 30
    argv = qemu_argv(lab, results, shares, "run", camera)
    console = os.path.join(results, "console.log")
    started = time.monotonic()
    with open(os.path.join(results, "qemu.log"), "w", encoding="utf-8") as qlog:
        proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=qlog, stderr=subprocess.STDOUT,
                                start_new_session=True)
    try:
        camera.start(results)
        booted = False
        while proc.poll() is None:
            elapsed = time.monotonic() - started
            if not booted and os.path.exists(os.path.join(results, "ready")):
                booted = True
                say(f"lab up in {elapsed:.1f} s")
            if not booted and elapsed > boot_timeout:
                raise LabFailed(f"the lab did not boot within {boot_timeout} s (BASALT_VLAB_BOOT_TIMEOUT)")
            if elapsed > budget:
                current = read(os.path.join(results, "current")).strip()
                raise LabFailed(f"the lab did not finish within {budget} s" +
                                (f" (job {current} was running)" if current else ""))
            time.sleep(0.2)
        if proc.returncode != 0:
            raise LabFailed(f"qemu exited with status {proc.returncode}: {read(os.path.join(results, 'qemu.log')).strip()}")
        if not os.path.exists(os.path.join(results, "done")):
            current = read(os.path.join(results, "current")).strip()
            raise LabFailed("the lab stopped before its jobs were done" + (f" (in job {current})" if current else "") +
                            ": a kernel panic or a failed set-up, see the console")
        say(f"lab finished in {time.monotonic() - started:.1f} s")
    except LabFailed as e:
        raise LabFailed(f"{e}\n---- console (last lines of {console}) ----\n{console_tail(console)}") from None
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        camera.stop()


def read(path):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return f.read()
    except OSError:
        return ""


def skip_reason_if_disabled():
    if os.environ.get("BASALT_SKIP_VLAB") == "1":
        return "BASALT_SKIP_VLAB=1 is set"
    return None


def describe_status(status):
    if status == 124:
        return "timed out inside the lab"
    if status > 128:
        try:
            name = signal.Signals(status - 128).name
        except ValueError:
            name = f"signal {status - 128}"
        return f"crashed inside the lab ({name})"
    return f"exit status {status}"


def print_fixtures(results):
    failed = [line for line in read(os.path.join(results, "fixtures")).splitlines() if not line.startswith("ok ")]
    for line in failed:
        say("fixture " + line)


def cmd_run(args):
    reason = skip_reason_if_disabled()
    if reason:
        raise LabUnavailable(reason)
    if not args.argv:
        say("usage: vlab.py run [--timeout S] -- PROGRAM ARGS...")
        return 2
    build_dir = args.build or default_build_dir()
    results = args.results or os.path.join(build_dir or cache_dir(), "vlab", "runs", "run")
    prog = args.argv[0]
    if not os.path.isabs(prog) and os.path.exists(prog):
        prog = os.path.abspath(prog)
    job = {"name": "run", "argv": [prog] + args.argv[1:], "timeout": args.timeout, "cwd": os.getcwd()}
    results, shares, camera = prepare(results, build_dir)
    write_jobs(results, [job])
    boot(results, shares, [job], args.boot_timeout, camera)
    print_fixtures(results)
    sys.stdout.write(read(os.path.join(results, "run.log")))
    sys.stdout.flush()
    status = int(read(os.path.join(results, "run.status")).strip() or 1)
    if status != 0:
        say(f"{prog}: {describe_status(status)}")
        if status == 124 or status > 128:
            say("console tail:\n" + console_tail(os.path.join(results, "console.log"), 15))
    return status


def cmd_batch(args):
    with open(args.jobs, encoding="utf-8") as f:
        jobs = json.load(f)["jobs"]
    build_dir = args.build or default_build_dir()
    results, shares, camera = prepare(args.results, build_dir)
    for job in jobs:
        job.setdefault("env", {})
        if job.get("gtest"):
            job["env"]["GTEST_OUTPUT"] = f"xml:{os.path.join(results, job['name'] + '.xml')}"
    try:
        write_jobs(results, jobs)
    except LabFailed:
        camera.stop()
        raise
    boot(results, shares, jobs, args.boot_timeout, camera)
    print_fixtures(results)
    worst = 0
    for job in jobs:
        status = int(read(os.path.join(results, job["name"] + ".status")).strip() or 1)
        say(f"job {job['name']}: {describe_status(status) if status else 'passed'}")
        if status:
            worst = 1
            print(read(os.path.join(results, job["name"] + ".log"))[-4000:])
    with open(os.path.join(results, "batch-ok"), "w", encoding="utf-8"):
        pass
    return 0 if not args.strict else worst


def cmd_result(args):
    """The result of one job, or of one gtest case of a job, from a batch run; exits 0 passed,
    1 failed, 77 skipped (with the reason, in GoogleTest's words)."""
    results = args.results
    unavailable = read(os.path.join(results, "unavailable")).strip()
    if unavailable:
        print(f"SKIPPED: the virtual lab did not run: {unavailable}")
        return EXIT_SKIP
    failed = read(os.path.join(results, "failed")).strip()
    if failed:
        print(f"the virtual lab failed, so {args.job} did not run:\n{failed}")
        return 1
    if not os.path.exists(os.path.join(results, "batch-ok")):
        print(f"no lab results in {results}: the lab's boot test (vlab.boot) did not run")
        return 1
    status_text = read(os.path.join(results, args.job + ".status")).strip()
    log = read(os.path.join(results, args.job + ".log"))
    if not status_text:
        print(f"{args.job} did not run in the lab")
        return 1
    status = int(status_text)
    if not args.case:
        print(log)
        return 0 if status == 0 else 1
    xml = os.path.join(results, args.job + ".xml")
    try:
        suite_name, case_name = args.case.split(".", 1)
        root = ET.parse(xml).getroot()
    except (OSError, ET.ParseError, ValueError) as e:
        print(log[-6000:])
        print(f"{args.job}: {describe_status(status)}; no GoogleTest results for {args.case} ({e})")
        return 1
    for suite in root.iter("testsuite"):
        if suite.get("name") != suite_name:
            continue
        for case in suite.iter("testcase"):
            if case.get("name") != case_name:
                continue
            return report_case(args.case, case, log)
    print(log[-6000:])
    print(f"{args.case} is not among the results of {args.job} ({describe_status(status)})")
    return 1


def report_case(name, case, log):
    out = case_output(log, name)
    if out:
        print(out)
    failures = case.findall("failure")
    skipped = case.find("skipped")
    if failures:
        for fail in failures:
            print(fail.get("message") or fail.text or "")
        return 1
    if skipped is not None or case.get("result") == "skipped":
        msg = (skipped.get("message") if skipped is not None else "") or "(no reason given)"
        if "[  SKIPPED ]" not in out:
            print(f"{msg}\n[  SKIPPED ] {name}")
        return EXIT_SKIP
    if case.get("status") == "notrun":
        print(f"SKIPPED: {name} is disabled")
        return EXIT_SKIP
    return 0


def case_output(log, name):
    """The lines GoogleTest printed for one case, from [ RUN ] to its closing line."""
    start = log.find(f"[ RUN      ] {name}\n")
    if start < 0:
        return ""
    m = re.compile(r"\[ {7}OK \] |\[  FAILED  \] |\[  SKIPPED \] ").search(log, start)
    end = log.find("\n", m.end()) if m else -1
    return log[start:end if end >= 0 else None]


def cmd_batch_entry(args):
    """batch with the lab's own failure modes written where `result` finds them."""
    os.makedirs(args.results, exist_ok=True)
    for marker in ("unavailable", "failed", "batch-ok"):
        try:
            os.unlink(os.path.join(args.results, marker))
        except FileNotFoundError:
            pass
    reason = skip_reason_if_disabled()
    try:
        if reason:
            raise LabUnavailable(reason)
        return cmd_batch(args)
    except LabUnavailable as e:
        os.makedirs(args.results, exist_ok=True)
        with open(os.path.join(args.results, "unavailable"), "w", encoding="utf-8") as f:
            f.write(str(e).replace("\n", " ") + "\n")
        print(f"SKIPPED: the virtual lab cannot run here: {e}")
        return EXIT_SKIP
    except LabFailed as e:
        with open(os.path.join(args.results, "failed"), "w", encoding="utf-8") as f:
            f.write(str(e) + "\n")
        print(f"vlab: error: {e}")
        return EXIT_LAB_FAILED


def cmd_shell(args):
    reason = skip_reason_if_disabled()
    if reason:
        raise LabUnavailable(reason)
    lab = build()
    build_dir = args.build or default_build_dir()
    results = os.path.join(build_dir or cache_dir(), "vlab", "runs", "shell")
    results, shares, camera = prepare(results, build_dir)
    argv = qemu_argv(lab, results, shares, "shell", camera)
    say("starting the lab shell (Ctrl-A X quits qemu)")
    proc = subprocess.Popen(argv)
    try:
        camera.start(results)
        return proc.wait()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        camera.stop()


def cmd_check(_args):
    reason = skip_reason_if_disabled()
    if reason:
        raise LabUnavailable(reason)
    lab = build()
    print(f"the virtual lab can run here: {lab}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("build")
    b.add_argument("--force", action="store_true")
    r = sub.add_parser("run")
    r.add_argument("--build", help="the build tree (writable in the lab; default: build/ of the source tree)")
    r.add_argument("--results", help="where the run's files go (default: BUILD/vlab/runs/run)")
    r.add_argument("--timeout", type=int, default=300, help="seconds the program may run (default 300)")
    r.add_argument("--boot-timeout", type=int, default=int(os.environ.get("BASALT_VLAB_BOOT_TIMEOUT", "120")))
    r.add_argument("argv", nargs=argparse.REMAINDER)
    bt = sub.add_parser("batch")
    bt.add_argument("--jobs", required=True)
    bt.add_argument("--results", required=True)
    bt.add_argument("--build")
    bt.add_argument("--strict", action="store_true", help="exit 1 when a job failed")
    bt.add_argument("--boot-timeout", type=int, default=int(os.environ.get("BASALT_VLAB_BOOT_TIMEOUT", "120")))
    rs = sub.add_parser("result")
    rs.add_argument("--results", required=True)
    rs.add_argument("--job", required=True)
    rs.add_argument("--case")
    sh = sub.add_parser("shell")
    sh.add_argument("--build")
    sub.add_parser("check")
    args = parser.parse_args()
    if getattr(args, "argv", None) and args.argv[0] == "--":
        args.argv = args.argv[1:]
    try:
        if args.cmd == "build":
            print(build(force=args.force))
            return 0
        if args.cmd == "batch":
            return cmd_batch_entry(args)
        if args.cmd == "result":
            return cmd_result(args)
        if args.cmd == "run":
            return cmd_run(args)
        if args.cmd == "shell":
            return cmd_shell(args)
        return cmd_check(args)
    except LabUnavailable as e:
        print(f"SKIPPED: the virtual lab cannot run here: {e}")
        return EXIT_SKIP
    except LabFailed as e:
        print(f"vlab: error: {e}", file=sys.stderr)
        return EXIT_LAB_FAILED


if __name__ == "__main__":
    sys.exit(main())

# The virtual lab's fixtures and job runner, run by the initramfs' /init (busybox sh) with the
# host's root mounted read-only at /host. It loads the drivers, builds the devices the tests
# use, writes the environment contract (tools/vlab/README.md) to /run/basalt-vlab/env, then runs
# the jobs the host asked for (or a shell) inside `chroot /host`, and powers off.
#
# What each fixture is, and the result of setting it up, goes to $results/fixtures
# ("ok NAME detail" or "fail NAME why"), so the host and the self-tests can say what is missing.
# A fixture that fails leaves its variables unset; the lab itself goes on.

export PATH=/bin:/sbin:/usr/bin:/usr/sbin
results=$BASALT_VLAB_RESULTS
hr=/host$results
say() { echo "basalt-vlab: $*" >/dev/console; }
# timeline: seconds since the kernel started, when each fixture was done (for boot-time figures).
stamp() {
  read -r _up _idle </proc/uptime
  echo "$_up $1" >>"$hr/timeline"
}
fixture_ok() {
  echo "ok $1 $2" >>"$hr/fixtures"
  stamp "$1"
}
fixture_fail() {
  stamp "$1"
  echo "fail $1 $2" >>"$hr/fixtures"
  say "fixture $1 FAILED: $2"
}
stop() {
  sync
  poweroff -f
  sleep 30
}

[ -d "$hr" ] || {
  say "error: the results folder $results is not writable in the guest"
  stop
}
: >"$hr/fixtures"
stamp start
# lab.conf (written by the host runner): BASALT_VLAB_SRC, BASALT_VLAB_TOOLS, jobs.
[ -f "$hr/lab.conf" ] && . "$hr/lab.conf"

run_dir=/host/run/basalt-vlab
mkdir -p "$run_dir"
env_file=$run_dir/env
{
  echo "export BASALT_VLAB=1"
  echo "export BASALT_VLAB_RESULTS=$results"
} >"$env_file"
setenv() { echo "export $1=$2" >>"$env_file"; }
in_host() { # runs a command line inside the host root with the lab's environment
  chroot /host /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    HOME=/root TERM="${TERM:-linux}" LANG=C.UTF-8 /bin/sh -c ". /run/basalt-vlab/env; $1"
}

load() {
  modprobe "$@" 2>>"$hr/modprobe.log"
}

wait_for() { # wait_for SECONDS TEST...: polls every 0.1 s
  _wait_left=$(($1 * 10))
  shift
  while [ $_wait_left -gt 0 ]; do
    "$@" && return 0
    usleep 100000
    _wait_left=$((_wait_left - 1))
  done
  return 1
}

video_node_named() { # the /dev/videoN whose sysfs name is $1
  for d in /sys/class/video4linux/video*; do
    [ -f "$d/name" ] && [ "$(cat "$d/name")" = "$1" ] && {
      echo "/dev/${d##*/}"
      return 0
    }
  done
  return 1
}

video_node_of_driver() { # the capture /dev/videoN bound to driver $1 (index 0 only)
  for d in /sys/class/video4linux/video*; do
    drv=$(readlink "$d/device/driver" 2>/dev/null) || continue
    [ "${drv##*/}" = "$1" ] || continue
    [ "$(cat "$d/index" 2>/dev/null)" = 0 ] || continue
    echo "/dev/${d##*/}"
    return 0
  done
  return 1
}

# ---- loopback: the shows' status servers listen on 127.0.0.1 -------------------------------
if ip link set lo up 2>/dev/null || ifconfig lo 127.0.0.1 up 2>/dev/null; then
  setenv BASALT_VLAB_LOOPBACK 1
  fixture_ok loopback "lo is up (127.0.0.1)"
else
  fixture_fail loopback "cannot bring lo up: the status-server cases cannot connect"
fi

# ---- V4L2: vivid, instance 0 a webcam, instance 1 an HDMI input, instance 2 two webcams ---------
# node_types 0x1: a video capture node only; input_types: 2 bits per input, 00 webcam, 11 HDMI.
if load vivid n_devs=3 node_types=0x1,0x1,0x1 num_inputs=1,1,2 input_types=0x0,0x3,0x0; then
  if webcam=$(video_node_named vivid-000-vid-cap); then
    setenv BASALT_VLAB_V4L2_WEBCAM "$webcam"
    fixture_ok webcam "$webcam (vivid instance 0, input 0: webcam)"
  else
    fixture_fail webcam "vivid loaded but no vivid-000-vid-cap node"
  fi
  if hdmi=$(video_node_named vivid-001-vid-cap); then
    setenv BASALT_VLAB_V4L2_HDMI "$hdmi"
    fixture_ok hdmi "$hdmi (vivid instance 1, input 0: HDMI with DV timings)"
  else
    fixture_fail hdmi "vivid loaded but no vivid-001-vid-cap node"
  fi
  if inputs=$(video_node_named vivid-002-vid-cap); then
    setenv BASALT_VLAB_V4L2_INPUTS "$inputs"
    fixture_ok inputs "$inputs (vivid instance 2: two webcam inputs)"
  else
    fixture_fail inputs "vivid loaded but no vivid-002-vid-cap node"
  fi
else
  fixture_fail webcam "modprobe vivid failed: $(tail -1 "$hr/modprobe.log")"
  fixture_fail hdmi "modprobe vivid failed"
fi

# The UVC camera is plugged into qemu's xHCI from the start: load its drivers now, so that it
# enumerates while the other fixtures are set up (uvc_camera.sh waits for it below).
load xhci_pci
load uvcvideo

# ---- sound: ALSA's loopback card (what is played on device 0 is captured on device 1) ---------
if load snd_aloop && wait_for 5 grep -q Loopback /proc/asound/cards; then
  setenv BASALT_VLAB_ALSA_LOOPBACK "hw:Loopback,1,0"
  fixture_ok alsa "snd-aloop: the default output is card Loopback, captured back on hw:Loopback,1,0"
else
  fixture_fail alsa "modprobe snd_aloop failed or no Loopback card appeared"
fi

# ---- MIDI: ALSA's sequencer (the midi backend's contract case makes a port of its own on it),
# its dummy "Midi Through" client and a snd-virmidi card whose rawmidi nodes are sequencer ports
if load snd_seq && wait_for 5 test -c /dev/snd/seq; then
  load snd_seq_dummy || true
  load snd_virmidi || true
  setenv BASALT_VLAB_MIDI_SEQ /dev/snd/seq
  fixture_ok midi "snd-seq: /dev/snd/seq$(ls /dev/snd/midiC*D0 2>/dev/null | head -1 | sed 's/^/, virmidi /')"
else
  fixture_fail midi "modprobe snd_seq failed or no /dev/snd/seq appeared"
fi

# ---- uhid ---------------------------------------------------------------------------------
if load uhid && wait_for 2 test -c /dev/uhid; then
  setenv BASALT_VLAB_UHID 1
  fixture_ok uhid "/dev/uhid"
else
  fixture_fail uhid "modprobe uhid failed or /dev/uhid did not appear"
fi

# ---- evdev and uinput: keyboards and mice made by the tests themselves ----------------------
if load evdev && load uinput && wait_for 2 test -c /dev/uinput; then
  setenv BASALT_VLAB_UINPUT /dev/uinput
  fixture_ok uinput "/dev/uinput (evdev nodes under /dev/input)"
else
  fixture_fail uinput "modprobe evdev/uinput failed or /dev/uinput did not appear: $(tail -1 "$hr/modprobe.log")"
fi

# ---- DRM: virtio-gpu (qemu -device virtio-gpu-pci) -----------------------------------------
load virtio_gpu
drm=
for c in /sys/class/drm/card[0-9]*; do
  case "$c" in *-*) continue ;; esac
  drv=$(readlink "$c/device/driver" 2>/dev/null)
  case "${drv##*/}" in virtio_gpu | virtio-gpu) drm=/dev/dri/${c##*/} ;; esac
  # virtio-gpu sits on a virtio bus device under PCI; its driver link is "virtio_gpu".
done
if [ -z "$drm" ]; then
  for c in /sys/class/drm/card[0-9]*; do
    case "$c" in *-*) continue ;; esac
    [ -e "$c/device/driver" ] && grep -q virtio "$c/device/uevent" 2>/dev/null && drm=/dev/dri/${c##*/}
  done
fi
if [ -n "$drm" ] && [ -c "$drm" ]; then
  setenv BASALT_VLAB_DRM "$drm"
  fixture_ok drm "$drm (virtio-gpu)"
else
  fixture_fail drm "no virtio-gpu DRM card (qemu needs -device virtio-gpu-pci; modprobe: $(tail -1 "$hr/modprobe.log"))"
fi

# ---- USB gadgets on dummy_hcd: one UDC (and host controller) per gadget ----------------------
cfs=/sys/kernel/config
load configfs && { grep -q " $cfs " /proc/mounts || mount -t configfs none $cfs; }
# The host root's /sys was bind-mounted before configfs existed: mount it there too.
mount -t configfs none /host$cfs
load dummy_hcd num=2 && load libcomposite && load usb_f_hid && load usbhid && load hid_generic && load uvcvideo
gadgets=$cfs/usb_gadget
state=$run_dir/gadgets
: >"$state"

# hex "05 01 ..." -> raw bytes on stdout
hex_bytes() { for b in $1; do printf %b "\\0$(printf %03o 0x$b)"; done; }

make_hid_gadget() { # NAME UDC VID PID PRODUCT REPORT_LENGTH DESCRIPTOR_HEX
  g=$gadgets/$1
  mkdir -p "$g" || return 1
  echo "0x$3" >"$g/idVendor"
  echo "0x$4" >"$g/idProduct"
  echo 0x0100 >"$g/bcdDevice"
  echo 0x0200 >"$g/bcdUSB"
  mkdir -p "$g/strings/0x409"
  echo "Basalt virtual lab" >"$g/strings/0x409/manufacturer"
  echo "$5" >"$g/strings/0x409/product"
  echo "vlab-$1" >"$g/strings/0x409/serialnumber"
  f=$g/functions/hid.usb0
  mkdir -p "$f" || return 1
  echo 0 >"$f/protocol"
  echo 0 >"$f/subclass"
  echo "$6" >"$f/report_length"
  # configfs stores what one write() brings: the descriptor must arrive in a single write.
  hex_bytes "$7" >/tmp/report_desc.bin
  cat /tmp/report_desc.bin >"$f/report_desc"
  mkdir -p "$g/configs/c.1/strings/0x409"
  echo "$1" >"$g/configs/c.1/strings/0x409/configuration"
  echo 100 >"$g/configs/c.1/MaxPower"
  ln -s "$f" "$g/configs/c.1/" || return 1
  echo "$2" >"$g/UDC" || return 1
  echo "$1 $2" >>"$state"
}

hidg_of() { # the /dev/hidgN of gadget $1 (its function's dev is MAJOR:MINOR)
  dev=$(cat "$gadgets/$1/functions/hid.usb0/dev" 2>/dev/null) || return 1
  for n in /sys/class/hidg/hidg*; do
    [ "$(cat "$n/dev")" = "$dev" ] && {
      echo "/dev/${n##*/}"
      return 0
    }
  done
  return 1
}

hidraw_of() { # the /dev/hidrawN whose HID_ID is 0003:0000VVVV:0000PPPP (upper case)
  for n in /sys/class/hidraw/hidraw*; do
    grep -qi "HID_ID=0003:0000$1:0000$2" "$n/device/uevent" 2>/dev/null && {
      echo "/dev/${n##*/}"
      return 0
    }
  done
  return 1
}

usb_device_of() { # the host-side sysfs USB device with idVendor $1 and idProduct $2
  for d in /sys/bus/usb/devices/*; do
    [ "$(cat "$d/idVendor" 2>/dev/null)" = "$1" ] && [ "$(cat "$d/idProduct" 2>/dev/null)" = "$2" ] && {
      echo "$d"
      return 0
    }
  done
  return 1
}

# The lab's dial box (Basalt's own descriptor, pid.codes test ids 1209:0001): a Multi-axis
# Controller with 8 buttons (byte 0, bit n = button n+1) and 8 relative dials as signed bytes
# (bytes 1-8: X, Y, Z, Rx, Ry, Rz, Dial, Wheel). Input report: 9 bytes, no report id.
DIAL_DESC="05 01 09 08 a1 01 05 09 19 01 29 08 15 00 25 01 75 01 95 08 81 02
  05 01 09 30 09 31 09 32 09 33 09 34 09 35 09 37 09 38 15 81 25 7f 75 08 95 08 81 06 c0"
# The PowerMate's report format (6 bytes: byte 0 bit 0 the button, byte 1 the signed rotation,
# bytes 2-5 LED state) under its ids; the HID core ignores 077d:0410, so no hidraw appears.
POWERMATE_DESC="05 01 09 37 a1 01 05 09 09 01 15 00 25 01 75 01 95 01 81 02 75 07 95 01 81 01
  05 01 09 37 15 81 25 7f 75 08 95 01 81 06 06 00 ff 09 01 15 00 26 ff 00 75 08 95 04 81 02 c0"

if [ -d /sys/class/udc ] && [ -d $gadgets ]; then
  if make_hid_gadget dial dummy_udc.0 1209 0001 "Basalt Lab Dial Box" 9 "$DIAL_DESC"; then
    if wait_for 10 hidraw_of 1209 0001 >/dev/null && hidg=$(hidg_of dial); then
      setenv BASALT_VLAB_HID_DIAL 1209:0001
      setenv BASALT_VLAB_HID_DIAL_GADGET "$hidg"
      fixture_ok dial "1209:0001 on dummy_udc.0, gadget $hidg, host $(hidraw_of 1209 0001)"
    else
      fixture_fail dial "the dial gadget did not enumerate with a hidraw node within 10 s"
    fi
  else
    fixture_fail dial "cannot create the configfs HID gadget (libcomposite/usb_f_hid: $(tail -1 "$hr/modprobe.log"))"
  fi
  if make_hid_gadget powermate dummy_udc.1 077d 0410 "Griffin PowerMate" 6 "$POWERMATE_DESC"; then
    if wait_for 10 usb_device_of 077d 0410 >/dev/null && hidg=$(hidg_of powermate); then
      setenv BASALT_VLAB_HID_POWERMATE 077d:0410
      setenv BASALT_VLAB_HID_POWERMATE_GADGET "$hidg"
      fixture_ok powermate "077d:0410 on dummy_udc.1, gadget $hidg, host $(usb_device_of 077d 0410)"
    else
      fixture_fail powermate "the PowerMate gadget did not enumerate within 10 s"
    fi
  else
    fixture_fail powermate "cannot create the configfs HID gadget"
  fi
else
  fixture_fail dial "no USB device controller (dummy_hcd) or no configfs usb_gadget"
  fixture_fail powermate "no USB device controller (dummy_hcd) or no configfs usb_gadget"
fi

# ---- the UVC camera (on the host, through qemu's usb-redir) and vhci_hcd -------------------
. "/host$BASALT_VLAB_SRC/tools/vlab/guest/uvc_camera.sh"

# ---- udev: the host's systemd-udevd, as on a real machine --------------------------------
# libcamera enumerates only devices udevd has processed (libudev's "is initialized" match) and
# learns of hotplug from udevd; other programs that use libudev do too. Started once the
# fixtures exist (started first, its start-up slows theirs down under TCG). The lab's programs
# run in a chroot, which systemd's tools refuse to work in unless told to ignore it.
# udevd gets the rules for devices and cameras only (permissions, /dev/v4l links): the host's
# full set, parsed and run under TCG, would add seconds to every boot for devices no test reads.
setenv SYSTEMD_IGNORE_CHROOT 1
udev_rules=/host/usr/lib/udev/rules.d
mkdir -p /host/run/basalt-vlab/udev-rules
for r in 50-udev-default.rules 60-persistent-v4l.rules; do
  [ -f "$udev_rules/$r" ] && cp "$udev_rules/$r" /host/run/basalt-vlab/udev-rules/
done
[ -d "$udev_rules" ] && mount --bind /host/run/basalt-vlab/udev-rules "$udev_rules"
if ! in_host "test -x /lib/systemd/systemd-udevd"; then
  fixture_fail udev "the host has no systemd-udevd (Debian package udev; scripts/setup.sh --test): libcamera sees no camera without it"
elif in_host "/lib/systemd/systemd-udevd --daemon && udevadm trigger --settle --action=add --subsystem-match=video4linux --subsystem-match=media" >"$hr/udev.log" 2>&1; then
  setenv BASALT_VLAB_UDEV 1
  fixture_ok udev "systemd-udevd runs; video4linux and media devices processed"
else
  fixture_fail udev "systemd-udevd did not start or settle: $(tail -1 "$hr/udev.log")"
fi

setenv BASALT_VLAB_GADGET_CTL "$BASALT_VLAB_SRC/tools/vlab/guest/gadget-ctl"
if [ -n "$BASALT_VLAB_TOOLS" ] && [ -x "/host$BASALT_VLAB_TOOLS/basalt-vlab-hid-replay" ]; then
  setenv BASALT_VLAB_HID_REPLAY "$BASALT_VLAB_TOOLS/basalt-vlab-hid-replay"
fi
cp "$env_file" "$hr/lab.env"
stamp ready
say "fixtures ready"
: >"$hr/ready"

# ---- jobs, or a shell ---------------------------------------------------------------------

if [ "$BASALT_VLAB_MODE" = shell ]; then
  say "interactive lab shell: the host's root, the lab's devices; 'exit' powers off"
  cat "$env_file" >/dev/console
  setsid cttyhack chroot /host /usr/bin/env PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    HOME=/root TERM=linux /bin/sh -c ". /run/basalt-vlab/env; cd \"$BASALT_VLAB_SRC\"; exec /bin/bash -i"
  stop
fi

# Jobs: $hr/jobs has one line per job, "NAME TIMEOUT"; $hr/NAME.sh is its script. Output goes to
# NAME.log, the exit status to NAME.status (124: timed out, 128+N: killed by signal N).
if [ -f "$hr/jobs" ]; then
  while read -r name limit; do
    [ -n "$name" ] || continue
    echo "$name" >"$hr/current"
    say "job $name (limit ${limit} s)"
    in_host "exec timeout -k 5 $limit /bin/sh $results/$name.sh" >"$hr/$name.log" 2>&1 </dev/null
    echo $? >"$hr/$name.status"
    say "job $name: exit $(cat "$hr/$name.status")"
  done <"$hr/jobs"
fi
rm -f "$hr/current"
: >"$hr/done"
say "done"
stop

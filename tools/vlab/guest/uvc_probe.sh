# Sourced by uvc_camera.sh (in lab.sh) and gadget-ctl: where the lab's UVC camera is. Only shell
# built-ins in the loops (read, test): under TCG every process costs tens of milliseconds, and
# these run ten times a second while a test waits for a hotplug.

# The camera's USB device folder (1209:0002 behind a PCI host controller, not vhci_hcd).
uvc_usb_device() {
  for _d in /sys/bus/usb/devices/*-*; do
    case "$_d" in *:*) continue ;; esac                       # interfaces
    [ -e "$_d/../../vendor" ] || continue                     # not behind PCI (vhci_hcd, dummy_hcd)
    read -r _v 2>/dev/null <"$_d/idVendor" && [ "$_v" = 1209 ] || continue
    read -r _p 2>/dev/null <"$_d/idProduct" && [ "$_p" = 0002 ] || continue
    echo "$_d"
    return 0
  done
  return 1
}

# The camera's capture node: index 0 of the video nodes of its interface (index 1 is uvcvideo's
# metadata node).
uvc_node() {
  for _d in /sys/class/video4linux/video*; do
    read -r _i 2>/dev/null <"$_d/index" && [ "$_i" = 0 ] || continue
    read -r _v 2>/dev/null <"$_d/device/../idVendor" && [ "$_v" = 1209 ] || continue
    read -r _p 2>/dev/null <"$_d/device/../idProduct" && [ "$_p" = 0002 ] || continue
    [ -e "$_d/device/../../../vendor" ] || continue
    echo "/dev/${_d##*/}"
    return 0
  done
  return 1
}

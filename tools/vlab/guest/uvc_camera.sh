# Sourced by lab.sh: the lab's webcam. basalt-vlab-uvc-camera (tools/vlab/uvc) runs on the host,
# started by vlab.py, and qemu's usb-redir device plugs it into the guest's emulated xHCI
# (-device qemu-xhci), where uvcvideo binds it as a USB webcam (1209:0002, UVC 1.1, bulk
# streaming; YUYV and MJPEG). vhci_hcd is loaded too, so that tests can plug a second camera
# in through USB/IP (basalt-vlab-uvc-camera --vhci) inside the guest.
#
# Sets BASALT_VLAB_V4L2_UVC to the camera's capture node, BASALT_VLAB_UVC_CONTROL to the file
# gadget-ctl writes "unplug"/"plug" to (the camera answers in FILE.state), BASALT_VLAB_VHCI to
# vhci_hcd's sysfs folder.

uvc_control=$results/uvc-camera.request

. "/host$BASALT_VLAB_SRC/tools/vlab/guest/uvc_probe.sh"

if [ "${BASALT_VLAB_UVC_CAMERA:-}" != usbredir ]; then
  fixture_fail uvc "the host started no camera: ${BASALT_VLAB_UVC_CAMERA_MISSING:-vlab.py did not say why}"
elif ! load xhci_pci; then
  fixture_fail uvc "modprobe xhci_pci failed: $(tail -1 "$hr/modprobe.log")"
elif wait_for 60 uvc_node >/dev/null; then
  uvc=$(uvc_node)
  setenv BASALT_VLAB_V4L2_UVC "$uvc"
  setenv BASALT_VLAB_UVC_CONTROL "$uvc_control"
  echo "uvc usbredir" >>"$state"
  fixture_ok uvc "$uvc (uvcvideo; 1209:0002 on qemu-xhci through usb-redir)"
else
  fixture_fail uvc "the camera did not appear as a uvcvideo node within 60 s (camera: $(cat "$hr/uvc-camera.request.state" 2>/dev/null || echo no state); see $results/uvc-camera.log)"
fi

if load vhci_hcd && [ -d /sys/devices/platform/vhci_hcd.0 ]; then
  setenv BASALT_VLAB_VHCI /sys/devices/platform/vhci_hcd.0
  fixture_ok vhci "/sys/devices/platform/vhci_hcd.0 (USB/IP virtual host controller)"
else
  fixture_fail vhci "modprobe vhci_hcd failed: $(tail -1 "$hr/modprobe.log")"
fi

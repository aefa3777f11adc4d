# Sourced by lab.sh: a configfs UVC gadget (usb_f_uvc) on dummy_udc.2 that uvcvideo on the host
# side sees as a webcam offering uncompressed YUYV 320x240 at 10 and 5 frames per second, and
# the frame pump (basalt-vlab-uvc-pump) that answers the host's requests and feeds it frames.
#
# Sets BASALT_VLAB_V4L2_UVC to the uvcvideo capture node when the pump is running.

uvc_width=320
uvc_height=240

make_uvc_gadget() { # UDC
  g=$gadgets/uvc
  mkdir -p "$g" || return 1
  echo 0x1209 >"$g/idVendor"
  echo 0x0002 >"$g/idProduct"
  echo 0x0100 >"$g/bcdDevice"
  echo 0x0200 >"$g/bcdUSB"
  # A composite device with an interface association (as every UVC camera).
  echo 0xef >"$g/bDeviceClass"
  echo 0x02 >"$g/bDeviceSubClass"
  echo 0x01 >"$g/bDeviceProtocol"
  mkdir -p "$g/strings/0x409"
  echo "Basalt virtual lab" >"$g/strings/0x409/manufacturer"
  echo "Basalt Lab Camera" >"$g/strings/0x409/product"
  echo "vlab-uvc" >"$g/strings/0x409/serialnumber"
  f=$g/functions/uvc.0
  mkdir -p "$f" || return 1
  mkdir -p "$f/control/header/h"
  ln -s "$f/control/header/h" "$f/control/class/fs/"
  ln -s "$f/control/header/h" "$f/control/class/ss/"
  u=$f/streaming/uncompressed/u
  mkdir -p "$u/f1" || return 1
  echo $uvc_width >"$u/f1/wWidth"
  echo $uvc_height >"$u/f1/wHeight"
  echo $((uvc_width * uvc_height * 2)) >"$u/f1/dwMaxVideoFrameBufferSize"
  echo $((uvc_width * uvc_height * 16 * 5)) >"$u/f1/dwMinBitRate"
  echo $((uvc_width * uvc_height * 16 * 10)) >"$u/f1/dwMaxBitRate"
  echo 1000000 >"$u/f1/dwDefaultFrameInterval"
  printf '1000000\n2000000\n' >"$u/f1/dwFrameInterval"
  mkdir -p "$f/streaming/header/h"
  ln -s "$u" "$f/streaming/header/h/"
  ln -s "$f/streaming/header/h" "$f/streaming/class/fs/"
  ln -s "$f/streaming/header/h" "$f/streaming/class/hs/"
  ln -s "$f/streaming/header/h" "$f/streaming/class/ss/"
  echo 1024 >"$f/streaming_maxpacket"
  mkdir -p "$g/configs/c.1/strings/0x409"
  echo uvc >"$g/configs/c.1/strings/0x409/configuration"
  echo 100 >"$g/configs/c.1/MaxPower"
  ln -s "$f" "$g/configs/c.1/" || return 1
  echo "$1" >"$g/UDC" || return 1
  echo "uvc $1" >>"$state"
}

uvc_gadget_node() { # the gadget side's V4L2 output node of the UVC function
  for d in /sys/class/video4linux/video*; do
    drv=$(readlink "$d/device/driver" 2>/dev/null)
    case "$(cat "$d/name" 2>/dev/null)" in *dummy_udc*) ;; *) continue ;; esac
    echo "/dev/${d##*/}"
    return 0
  done
  return 1
}

if [ -d /sys/class/udc/dummy_udc.2 ] && [ -d $gadgets ]; then
  if make_uvc_gadget dummy_udc.2; then
    if wait_for 10 video_node_of_driver uvcvideo >/dev/null; then
      uvc=$(video_node_of_driver uvcvideo)
      fixture_ok uvc-enumerated "$uvc (uvcvideo), gadget $(uvc_gadget_node)"
      setenv BASALT_VLAB_V4L2_UVC "$uvc"
    else
      fixture_fail uvc "the UVC gadget did not enumerate as a uvcvideo node within 10 s"
    fi
  elif dmesg | grep -q "Unable to allocate streaming EP"; then
    # Known: dummy_hcd has no isochronous endpoints, and usb_f_uvc (kernel 6.1) streams only
    # isochronously, so the function cannot bind. Said so; the UVC tests skip with this reason.
    echo "" >"$gadgets/uvc/UDC" 2>/dev/null
    echo "unsupported uvc usb_f_uvc cannot bind on dummy_hcd: it needs an isochronous endpoint and dummy_hcd has none (kernel $(uname -r))" >>"$hr/fixtures"
  else
    fixture_fail uvc "cannot create the configfs UVC gadget"
  fi
else
  fixture_fail uvc "no third dummy UDC for the UVC gadget"
fi

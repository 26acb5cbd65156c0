// fmt_touch: heat map -> touch events
+incdir+rtl
rtl/fmt_touch.v
rtl/fmt_flatten.v
rtl/fmt_localmax.v
rtl/fmt_event_port.v
-f rtl/filelists/fmt_interp.f
-f rtl/filelists/fmt_tracker.f
-f rtl/filelists/fmt_blob.f

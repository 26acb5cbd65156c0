// fmt_touch: heat map -> touch events
+incdir+rtl
rtl/fmt_touch.v
rtl/fmt_flatten.v
-f rtl/filelists/fmt_localmax.f
rtl/fmt_event_port.v
-f rtl/filelists/fmt_interp.f
-f rtl/filelists/fmt_tracker.f
-f rtl/filelists/fmt_blob.f

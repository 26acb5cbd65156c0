// fmt_tracker: contact tracking
+incdir+rtl
rtl/fmt_tracker.v
rtl/fmt_tracker_vel.v

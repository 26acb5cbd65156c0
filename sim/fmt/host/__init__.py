"""Host side of the FMT core: the ``fmtctl`` tool and what it feeds.

  cli        the ``fmtctl`` command line (control port: registers, heat maps, events)
  events     event records of the stream, grouped into reports; sensor geometry
  tuio       reports -> TUIO 1.1 / 2.0 OSC messages (python-osc)
  uinput     reports -> Linux multitouch protocol-B input events (python-evdev)
  view       heat map + contacts renderer (matplotlib), live or from a recording
  recording  the .npz recording format (heat-map snapshots, events, settings)

None of these twins an RTL block; ``fmt.protocol`` is the control-port protocol.
"""

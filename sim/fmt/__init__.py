"""Golden model of the Fast Multi-Touch (FMT) controller.

Naming convention of the model twins:

* A block's model module is named after its RTL module without the ``fmt_`` prefix
  (``rtl/fmt_dds_bank.v`` -> ``fmt.dds_bank``).  One module may hold the twins of a
  small family; its docstring names every RTL module it twins.
* Inside it, the bit-exact twin of the RTL behaviour ends in ``_fixed`` and the
  floating-point accuracy reference of the same function ends in ``_float``
  (``dds_bank_fixed`` / ``dds_bank_float``, ``magnitude_fixed`` / ``magnitude_float``).
  A block that is integer-exact by nature has only the ``_fixed`` function
  (``local_maxima_fixed``, ``blob_stream_fixed``, ``track_fixed``).
* Modules that twin no single RTL block are named for what they do (params, regmap,
  generate, sensor, scene, chain, report, run_sim, settings, plots; the subpackage host:
  the fmtctl host tool and its outputs).

Module -> RTL modules it twins:

  fft_r22sdf  fmt_fft_r22sdf, fmt_fft_bf, fmt_fft_twiddle
  rx_array    fmt_rx_array, fmt_pair_split, fmt_magnitude, rtl/ref fmt_accum and
              fmt_col_pair_rx; also the floating-point receiver of the chain (``receive``)
  dds_bank    fmt_dds_bank (fmt_dds_chan, fmt_dds_rom2), fmt_tx (``tx_fixed``), fmt_despread
  pn_gen      fmt_pn_gen
  channel     bench/core/fmt_channel_sim.v (``channel_sim_fixed``; the rest of the module
              is the floating-point physics of transmit, sensor coupling and ADC)
  flatten     fmt_flatten
  localmax    fmt_localmax
  blob        fmt_blob
  interp      fmt_interp (fmt_interp_cordic, fmt_interp_lg, fmt_interp_exp, bias ROM)
  tracker     fmt_tracker
  event_port  fmt_event_port (cycle level)
  latency     fmt_latency (cycle level)
  touch       fmt_touch (the pipeline of the blocks above)
  protocol    fmt_ctrl_port (byte level; also the host side of scripts/fmtctl)
"""

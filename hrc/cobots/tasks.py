"""Background jobs of the cobots app: none yet. Cobot steps run on workers from issue 4 on,
through hrc.cobots.drivers.runner (one driver session per cobot per worker process)."""

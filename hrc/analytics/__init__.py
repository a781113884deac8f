"""Analytics of running cases: Gantt charts, cycle times, utilisation, waiting, XES export."""

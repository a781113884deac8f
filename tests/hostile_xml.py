"""Hostile XML that a PNML upload must refuse: one copy for the engine's and the API's tests."""

# Ten-fold entity expansion nine levels deep: under a kilobyte that unfolds to gigabytes.
BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE pnml [
  <!ENTITY lol "lol">
  <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
  <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
  <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
  <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
  <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
  <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
  <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
  <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
<name><text>&lol9;</text></name></net></pnml>"""

# An entity that would read a file from the server's disk into the pattern's name.
EXTERNAL_ENTITY = """<?xml version="1.0"?>
<!DOCTYPE pnml [<!ENTITY secret SYSTEM "file:///etc/passwd">]>
<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">
<name><text>&secret;</text></name></net></pnml>"""

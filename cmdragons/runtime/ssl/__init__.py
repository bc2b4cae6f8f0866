"""The league's protocols: SSL-Vision, tracker and referee packets over UDP multicast, grSim and the
simulation protocol, the SSL log file format; the adapters are stages on the bus."""

"""The bus's and the logs' protobuf schemas (``*.proto``, written from the league's published field
lists and our own messages) and their generated modules (``*_pb2.py``, checked in; rebuilt by
:mod:`cmdragons.runtime.proto.generate`)."""

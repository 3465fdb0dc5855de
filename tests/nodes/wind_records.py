"""Wind instrument records as the instruments send them, for the anemometer rostests."""
import functools


def xor_checksum(body):
    """NMEA 0183's and Gill's checksum: the XOR of the body's bytes."""
    return functools.reduce(lambda a, c: a ^ c, body.encode('ascii'), 0)


def nmea(body):
    """An NMEA 0183 sentence, '$<body>*<checksum>', without its line end."""
    return '$%s*%02X' % (body, xor_checksum(body))


def gill(body):
    """A Gill WindSonic record: STX <body> ETX <checksum>, without its line end."""
    return '\x02' + body + '\x03' + '%02X' % xor_checksum(body)

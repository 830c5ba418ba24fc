"""What several test modules share: small cases, the command line, CF checks."""

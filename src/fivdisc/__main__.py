from fivdisc.cli import main

main()

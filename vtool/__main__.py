from vtool.app.cli.main import main

main()

"""pythonfmu slaves for the dtcosim components and the code that builds them into FMUs."""

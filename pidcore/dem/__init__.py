"""pidcore.dem"""

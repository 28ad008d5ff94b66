"""pidcore.signal"""

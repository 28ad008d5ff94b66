"""pidcore.store"""

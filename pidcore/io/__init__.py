"""pidcore.io"""

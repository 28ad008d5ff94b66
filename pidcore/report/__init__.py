"""pidcore.report"""
